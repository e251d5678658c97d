"""Outputs are written whole (issue 15): through a temporary file or folder and a rename; a run into an existing
``--out`` replaces or clears only what the command writes; SIGINT and SIGTERM leave every file whole."""

from __future__ import annotations

import json
import os
import resource
import signal
import stat
import subprocess
import sys
import threading
import time
from pathlib import Path

import cv2
import pytest

from sid.cli import main
from sid.cli.common import (
    LOCK_NAME,
    OutputFolderInUse,
    Terminated,
    clear_owned,
    output_folder_lock,
    signals_as_interrupts,
    signals_deferred,
    staged_output,
)
from sid.documents import TEMPORARY_PREFIX
from tests.conftest import REPO_ROOT

SCENARIO = str(REPO_ROOT / "examples" / "conversation.json")


def test_staged_files_replace_the_earlier_run_and_stale_owned_ones_go(tmp_path):
    (tmp_path / "a.json").write_text("old")
    (tmp_path / "extra_1.png").write_text("stale")
    (tmp_path / "notes.txt").write_text("the user's")
    with staged_output(tmp_path, ("extra_*.png",)) as staged:
        (staged.path / "a.json").write_text("new")
        assert (tmp_path / "a.json").read_text() == "old"  # nothing moves before the run ends
        assert staged.final(staged.path / "a.json") == tmp_path / "a.json"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.json", "notes.txt"]
    assert (tmp_path / "a.json").read_text() == "new"


def test_a_failed_run_keeps_the_earlier_files_and_leaves_no_temporary_folder(tmp_path):
    (tmp_path / "a.json").write_text("old")
    with pytest.raises(KeyboardInterrupt), staged_output(tmp_path, ("a.json",)) as staged:
        (staged.path / "a.json").write_text("half")
        raise KeyboardInterrupt
    assert [p.name for p in tmp_path.iterdir()] == ["a.json"] and (tmp_path / "a.json").read_text() == "old"


def test_clear_owned_deletes_only_matching_files_and_leftover_temporaries(tmp_path):
    for name in ("overlay_000001.png", "topview_000001.png", "overlay.txt", "mine.png", f"{TEMPORARY_PREFIX}x"):
        (tmp_path / name).write_text("")
    (tmp_path / f"{TEMPORARY_PREFIX}dir").mkdir()
    removed = clear_owned(tmp_path, ("overlay_*.png", "topview_*.png"))
    assert len(removed) == 4
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mine.png", "overlay.txt"]


def test_costmap_into_an_existing_folder_replaces_its_files_and_keeps_others(tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    (out / "costmap.png").write_bytes(b"an earlier, broken picture")
    (out / "notes.txt").write_text("keep")
    (out / f"{TEMPORARY_PREFIX}killed").mkdir()  # a run killed with SIGKILL
    assert main(["costmap", SCENARIO, "--out", str(out)]) == 0
    names = sorted(p.name for p in out.iterdir())
    assert names == ["costmap.mcap", "costmap.npz", "costmap.pgm", "costmap.png", "costmap.yaml", "notes.txt"]
    assert cv2.imread(str(out / "costmap.png")) is not None
    assert f"wrote {out / 'costmap.png'}" in capsys.readouterr().out


def test_detect_rerun_clears_the_earlier_runs_pictures(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["detect", "--source", "synthetic:S1", "--frames", "3", "--out", str(out)]) == 0
    (out / "mine.txt").write_text("keep")
    assert main(["detect", "--source", "synthetic:S1", "--frames", "1", "--out", str(out)]) == 0
    assert sorted(p.name for p in out.iterdir()) == [
        "detections.jsonl",
        "mine.txt",
        "overlay_000000.png",
        "topview_000000.png",
    ]
    assert "removed 7 files of an earlier run" in capsys.readouterr().err


def test_every_file_detect_writes_has_the_permissions_of_the_users_umask(tmp_path, capsys):
    out = tmp_path / "out"
    previous = os.umask(0o027)
    try:
        assert main(["detect", "--source", "synthetic:S1", "--frames", "2", "--out", str(out)]) == 0
    finally:
        os.umask(previous)
    modes = {p.name: stat.S_IMODE(p.stat().st_mode) for p in out.iterdir()}
    assert "overlay_000000.png" in modes and "detections.jsonl" in modes
    assert set(modes.values()) == {0o640}, modes


def _detect_until_interrupted(out: Path, sig: signal.Signals) -> int:
    """Start ``sid detect --out`` on a long synthetic sequence, send ``sig`` once two frames are written; the exit
    code."""
    code = "import sys; from sid.cli import main; sys.exit(main(sys.argv[1:]))"
    argv = [sys.executable, "-c", code, "detect", "--source", "synthetic:S1", "--frames", "10000", "--out", str(out)]
    # A shell's background job starts with SIGINT ignored, and Python then keeps ignoring it (as a user's
    # background `sid` should): give the command the default disposition, whatever ran this test.
    # faulthandler on: a run that hangs is aborted below and prints where each of its threads stood.
    process = subprocess.Popen(
        argv,
        cwd=REPO_ROOT,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
        env={**os.environ, "PYTHONFAULTHANDLER": "1"},
    )
    try:
        deadline = time.monotonic() + 300  # a hang bound, not a speed check
        while len(list(out.glob("topview_*.png"))) < 2 and time.monotonic() < deadline and process.poll() is None:
            time.sleep(0.05)
        frames_before = len(list(out.glob("topview_*.png")))
        process.send_signal(sig)
        try:
            process.wait(timeout=300)
        except subprocess.TimeoutExpired:
            process.send_signal(signal.SIGABRT)  # faulthandler's dump of every thread, then the end
            _, err = process.communicate(timeout=60)
            pytest.fail(f"no exit within 300 s of {sig.name} ({frames_before} frames written before):\n{err.decode()}")
    finally:
        if process.poll() is None:
            process.kill()
    assert process.stderr is not None
    err = process.stderr.read().decode()
    assert "Traceback" not in err, err
    return process.returncode


@pytest.mark.slow
@pytest.mark.parametrize(("sig", "code"), [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_an_interrupted_detect_leaves_every_file_whole(tmp_path, sig, code):
    out = tmp_path / "out"
    assert _detect_until_interrupted(out, sig) == code
    lines = (out / "detections.jsonl").read_text().splitlines()
    frames = [json.loads(line)["frame"] for line in lines]  # every line whole
    overlays, tops = sorted(out.glob("overlay_*.png")), sorted(out.glob("topview_*.png"))
    assert [int(p.stem.split("_")[1]) for p in overlays] == frames  # each frame's line and both its pictures
    assert [int(p.stem.split("_")[1]) for p in tops] == frames
    assert all(cv2.imread(str(p)) is not None for p in overlays + tops)
    assert not [p for p in out.iterdir() if p.name.startswith(TEMPORARY_PREFIX)]
    assert os.path.getsize(out / "detections.jsonl") > 0


def _sid(*argv: str, **options) -> subprocess.Popen:
    """``python -m sid ARGV`` started in the repository, stderr piped."""
    return subprocess.Popen([sys.executable, "-m", "sid", *argv], cwd=REPO_ROOT, stderr=subprocess.PIPE, **options)


def test_a_second_run_on_a_held_folder_is_refused_and_leaves_the_first_runs_files(tmp_path):
    out = tmp_path / "out"
    with output_folder_lock(out):  # as a running `sid detect --out` or `sid demo --out` holds it
        (out / "overlay_000000.png").write_bytes(b"the first run's")
        for argv in (
            ["detect", "--source", "synthetic:S1", "--frames", "1", "--out", str(out)],
            ["costmap", SCENARIO, "--out", str(out)],
        ):
            second = _sid(*argv, stdout=subprocess.DEVNULL)
            _, err = second.communicate(timeout=300)
            assert second.returncode == 2
            assert f"{out}: another sid run is writing in this folder (pid {os.getpid()})" in err.decode()
        assert (out / "overlay_000000.png").read_bytes() == b"the first run's"
        assert sorted(p.name for p in out.iterdir()) == [LOCK_NAME, "overlay_000000.png"]
    assert not (out / LOCK_NAME).exists()  # released and removed at the end of the run
    with output_folder_lock(out):  # and free for the next one
        pass


def test_the_lock_of_a_killed_run_is_released(tmp_path):
    out = tmp_path / "out"
    holder = _sid("detect", "--source", "synthetic:S1", "--frames", "100000", "--out", str(out), stdout=subprocess.PIPE)
    assert holder.stdout is not None
    holder.stdout.readline()  # the first frame is out: the folder is held
    with pytest.raises(OutputFolderInUse, match=f"pid {holder.pid}"), output_folder_lock(out):
        pass
    holder.kill()
    holder.wait(timeout=60)
    with output_folder_lock(out):  # SIGKILL left the file, but the kernel released the lock
        assert (out / LOCK_NAME).read_text() == f"pid {os.getpid()}"


def test_two_demos_into_one_folder_the_second_is_refused_and_the_first_finishes(tmp_path):
    out = tmp_path / "demo"
    argv = ("demo", "--out", str(out), "--planner", "grid")
    first = _sid(*argv, stdout=subprocess.PIPE)
    assert first.stdout is not None
    first.stdout.readline()  # its first progress line: it is staging in the folder
    first.send_signal(signal.SIGSTOP)  # paused there, whatever the machine's speed
    try:
        second = _sid(*argv, stdout=subprocess.DEVNULL)
        _, second_err = second.communicate(timeout=300)
    finally:
        first.send_signal(signal.SIGCONT)
    first_out, first_err = first.communicate(timeout=300)
    assert second.returncode == 2 and "another sid run is writing in this folder" in second_err.decode()
    assert first.returncode in (0, 3), first_err.decode()  # 3: a planner found no path, the files still written
    assert {"comparison.png", "metrics.json", "scenario.json"} <= {p.name for p in out.iterdir()}
    assert not [p for p in out.iterdir() if p.name.startswith((TEMPORARY_PREFIX, LOCK_NAME))]


def test_a_frame_whose_line_cannot_be_written_keeps_none_of_its_pictures(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "detections.jsonl").symlink_to("/dev/full")  # every write of a line fails: ENOSPC, a full disk
    run = _sid("detect", "--source", "synthetic:S1", "--frames", "2", "--out", str(out), stdout=subprocess.PIPE)
    stdout, err = run.communicate(timeout=300)
    assert run.returncode == 1  # a failed run
    assert f"sid detect: cannot write {out / 'detections.jsonl'} (No space left on device)" in err.decode()
    assert stdout == b""  # the frame was not reported as written either
    assert sorted(p.name for p in out.iterdir()) == ["detections.jsonl"]  # no picture without its line


def test_a_frame_whose_picture_cannot_be_written_gets_no_line(tmp_path):
    out = tmp_path / "out"

    def small_files() -> None:  # a file may not pass 100 kB (an overlay is larger): its write fails as on a full disk
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (100_000, 100_000))

    run = _sid(
        "detect",
        "--source",
        "synthetic:S1",
        "--frames",
        "2",
        "--out",
        str(out),
        stdout=subprocess.PIPE,
        preexec_fn=small_files,
    )
    stdout, err = run.communicate(timeout=300)
    assert (
        run.returncode == 1
        and f"sid detect: cannot write {out / 'overlay_000000.png'} (File too large)" in err.decode()
    )
    assert stdout == b""
    assert sorted(p.name for p in out.iterdir()) == ["detections.jsonl"]
    assert (out / "detections.jsonl").read_bytes() == b""


def test_a_second_sigterm_does_not_interrupt_the_first_ones_clean_up():
    # `timeout 60 sid ...` sends SIGTERM to sid and then to its process group: the second one used to be raised
    # inside main's "interrupted" line, a traceback instead of exit 143.
    previous = signal.getsignal(signal.SIGTERM)
    with signals_as_interrupts():
        with pytest.raises(Terminated):
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(5)  # the handler raises at the next bytecode
        try:
            os.kill(os.getpid(), signal.SIGTERM)  # ignored: no second Terminated
            time.sleep(0.1)
        except Terminated:
            pytest.fail("the second SIGTERM was raised too")
    assert signal.getsignal(signal.SIGTERM) == previous


@pytest.mark.parametrize("number", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_another_thread_receives_waits_for_the_deferred_set(number):
    # sid detect reads ahead in a worker thread: a signal the kernel hands to that thread used to reach the main
    # thread's handler inside the deferred set (an overlay written, its line not).
    entered, sent = threading.Event(), threading.Event()

    def send() -> None:
        entered.wait(5)
        os.kill(os.getpid(), number)  # to the process: the kernel may hand it to either thread
        sent.set()

    worker = threading.Thread(target=send)
    finished = False
    # A background job (CI runs two suites side by side) starts with SIGINT ignored: give it Python's own handler.
    interrupt = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with signals_as_interrupts(), pytest.raises(KeyboardInterrupt):  # Terminated for SIGTERM
            worker.start()
            with signals_deferred():
                entered.set()
                assert sent.wait(5)
                time.sleep(0.2)  # a handler due now would raise here
                finished = True
    finally:
        signal.signal(signal.SIGINT, interrupt)
    worker.join()
    assert finished


def test_a_signal_ignored_before_stays_ignored_after_the_deferred_set():
    interrupt = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        with signals_deferred():
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.1)
        time.sleep(0.1)  # nothing raised: the signal went to the handler restored, SIG_IGN
        assert signal.getsignal(signal.SIGINT) == signal.SIG_IGN
    finally:
        signal.signal(signal.SIGINT, interrupt)


def test_signals_deferred_restores_the_handlers_and_delivers_nothing_when_none_came():
    before = signal.getsignal(signal.SIGINT), signal.getsignal(signal.SIGTERM)
    with signals_deferred():
        pass
    assert (signal.getsignal(signal.SIGINT), signal.getsignal(signal.SIGTERM)) == before

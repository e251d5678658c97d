"""``sid groups`` and ``sid eval fformation`` on the command line."""

from __future__ import annotations

import io
import json
import math
import subprocess
import sys

import cv2
import numpy as np
import pytest
import scipy.io

from sid.cli import main
from sid.experiments.fformation import DEFAULT_GRID
from tests.conftest import REPO_ROOT, shared_path
from tests.experiments.test_fformation import tiny_frames, write_sequence

PAIR = {
    "frame": 0,
    "people": [{"id": 1, "x": 2.0, "y": 0.0, "theta": 0.0}, {"id": 2, "x": 2.8, "y": 0.0, "theta": math.pi}],
}
APART = {"frame": 2, "people": [{"id": 5, "x": 1.0, "y": 0.0, "theta": None}, {"id": 6, "x": 1.0, "y": 1.0}]}


def run_sid(argv: list[str], capsys) -> tuple[int, list[str], str]:
    code = main(argv)
    captured = capsys.readouterr()
    return code, captured.out.splitlines(), captured.err


def test_groups_reads_json_lines_and_writes_one_line_per_frame(tmp_path, capsys):
    source = tmp_path / "frames.jsonl"
    source.write_text(json.dumps(PAIR) + "\n\n" + json.dumps(APART) + "\n")
    code, out, err = run_sid(["groups", str(source)], capsys)
    assert code == 0 and err == ""
    first, second = (json.loads(line) for line in out)
    assert first["frame"] == 0 and len(first["groups"]) == 1
    group = first["groups"][0]
    assert group["members"] == [1, 2] and group["area"] == 0.0
    assert group["interest_point"] == pytest.approx([2.4, 0.0]) and group["spread"] == pytest.approx(0.4)
    assert group["zone"] == [pytest.approx([2.4, 0.0])]
    assert second == {"frame": 2, "groups": []}


def test_malformed_lines_are_reported_with_their_number_and_skipped(tmp_path, capsys):
    lines = [
        json.dumps(PAIR),
        "{not json",
        json.dumps({"frame": 1, "people": [{"id": 1, "x": "far", "y": 0.0, "theta": 0.0}]}),
        json.dumps({"frame": 1, "people": [{"id": 1, "x": 0.0, "y": 0.0}, {"id": 1, "x": 1.0, "y": 0.0}]}),
        '{"frame": 1, "people": [{"id": 3, "x": NaN, "y": 0.0}]}',
        json.dumps([1, 2]),
        json.dumps({"frame": 9, "people": []}),
        '{"frame": 1e400, "people": []}',  # would be echoed as Infinity, which is not JSON
        json.dumps({"frame": "take 2", "people": []}),
    ]
    source = tmp_path / "frames.jsonl"
    source.write_text("\n".join(lines) + "\n")
    code, out, err = run_sid(["groups", str(source)], capsys)
    assert code == 0
    assert [json.loads(line)["frame"] for line in out] == [0, 9, "take 2"]
    assert "line 8: 'frame' must be a finite number or a string, got Infinity" in err
    assert "line 2: not valid JSON" in err
    assert 'line 3: people[0] (id 1): x must be a finite number of metres, got "far"' in err
    assert "line 4: groups: person ids must be unique" in err
    assert "line 5: not valid JSON (NaN is not a number)" in err
    assert "line 6: expected a JSON object" in err
    assert "skipped 6 malformed lines" in err


def test_a_number_too_large_for_a_float_is_a_malformed_line(capsys, monkeypatch):
    huge = "1" + "0" * 400  # a JSON int no float can hold (it used to end the run with an OverflowError)
    monkeypatch.setattr(sys, "stdin", io.StringIO(f'{{"frame": {huge}, "people": []}}\n' + json.dumps(PAIR) + "\n"))
    code, out, err = run_sid(["groups", "-"], capsys)
    assert code == 0 and [json.loads(line)["frame"] for line in out] == [0]
    first = err.splitlines()[0]  # the value's summary, cut to 80 characters
    assert first == f"sid groups: line 1: 'frame' must be a finite number or a string, got {huge[:77]}..."


def test_strict_stops_at_the_first_bad_line_keeping_earlier_output(tmp_path, capsys):
    source = tmp_path / "frames.jsonl"
    source.write_text(json.dumps(PAIR) + "\n" + '{"people": 3}\n' + json.dumps(PAIR) + "\n")
    code, out, err = run_sid(["groups", "--strict", str(source)], capsys)
    assert code == 2  # bad input
    assert len(out) == 1 and json.loads(out[0])["frame"] == 0
    assert "line 2: 'people' must be a list" in err


def test_group_params_come_from_the_options(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(sys, "stdin", io.StringIO(json.dumps(PAIR) + "\n"))
    code, out, _ = run_sid(["groups", "-", "--method", "rays", "--spread-threshold", "0.3"], capsys)
    assert code == 0 and json.loads(out[0])["groups"] == []  # D = 0.4 m > 0.3 m
    monkeypatch.setattr(sys, "stdin", io.StringIO(json.dumps(PAIR) + "\n"))
    code, out, _ = run_sid(["groups", "-", "--alone-price", "0.005"], capsys)
    assert code == 0 and json.loads(out[0])["groups"] == []  # the o-space method: two alone cost less than a group
    code, _, err = run_sid(["groups", "-", "--eps", "-1"], capsys)
    assert code == 2 and "eps must be a positive" in err
    code, _, err = run_sid(["groups", str(tmp_path / "missing.jsonl")], capsys)
    assert code == 2 and "cannot read" in err


# Regression fixture (issue 15): a UTF-8 byte-order mark, Latin-1 bytes, raw binary, then good lines again.
NOT_UTF8 = b"\n".join(
    [
        b"\xef\xbb\xbf" + json.dumps(PAIR).encode(),
        b'{"frame": 1, "people": [], "note": "caf\xe9"}',
        b"\x00\xff\xfe\x89PNG",
        json.dumps(APART).encode(),
        b"",
    ]
)


def test_lines_that_are_not_utf8_are_reported_and_skipped(tmp_path, capsys):
    source = tmp_path / "frames.jsonl"
    source.write_bytes(NOT_UTF8)
    code, out, err = run_sid(["groups", str(source)], capsys)
    assert code == 0
    assert [json.loads(line)["frame"] for line in out] == [0, 2]  # the BOM line and the line after the bad bytes
    assert err.splitlines() == [
        "sid groups: line 2: not UTF-8 text (byte 0xe9 at byte 40 of the line)",
        "sid groups: line 3: not UTF-8 text (byte 0xff at byte 2 of the line)",
        "sid groups: skipped 2 malformed lines",
    ]
    code, out, err = run_sid(["groups", "--strict", str(source)], capsys)
    assert (
        code == 2
        and len(out) == 1
        and err.splitlines() == ["sid groups: line 2: not UTF-8 text (byte 0xe9 at byte 40 of the line)"]
    )


def test_a_utf16_file_is_named_as_such(tmp_path, capsys):
    source = tmp_path / "frames.jsonl"
    source.write_text(json.dumps(PAIR) + "\n", encoding="utf-16")
    code, out, err = run_sid(["groups", "--strict", str(source)], capsys)
    assert code == 2 and out == []
    assert err == "sid groups: line 1: not UTF-8 text (it starts with a UTF-16 byte-order mark; save it as UTF-8)\n"


def test_stdin_bytes_are_decoded_line_by_line():
    done = subprocess.run(
        [sys.executable, "-m", "sid", "groups", "-"], input=NOT_UTF8, capture_output=True, cwd=REPO_ROOT, timeout=60
    )
    assert done.returncode == 0
    assert [json.loads(line)["frame"] for line in done.stdout.splitlines()] == [0, 2]
    assert b"Traceback" not in done.stderr and b"line 3: not UTF-8 text" in done.stderr


def test_a_folder_as_input_is_one_line(tmp_path, capsys):
    code, out, err = run_sid(["groups", str(tmp_path)], capsys)
    assert code == 2 and out == [] and err.count("\n") == 1 and "cannot read" in err


def test_output_is_flushed_line_by_line_through_a_pipe():
    # A consumer reading the first output line must get it before the input ends.
    process = subprocess.Popen(
        [sys.executable, "-m", "sid", "groups", "-"],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
        cwd=REPO_ROOT,
    )
    assert process.stdin and process.stdout
    process.stdin.write(json.dumps(PAIR) + "\n")
    process.stdin.flush()
    first = process.stdout.readline()
    process.stdin.close()
    assert json.loads(first)["groups"][0]["members"] == [1, 2]
    assert process.wait(timeout=30) == 0


def test_eval_fformation_prints_json_and_a_table(tmp_path, capsys):
    tiny = write_sequence(tmp_path / "Tiny", tiny_frames(), {1: [[1, 2]], 2: [[1, 2, 3]], 3: [[4, 5]]})
    code, out, _ = run_sid(["eval", "fformation", str(tiny), "--scale", "0.01"], capsys)
    assert code == 0
    report = json.loads("\n".join(out))
    assert report["scores"]["Tiny"]["2/3"] == pytest.approx({"precision": 1.0, "recall": 2 / 3, "f1": 0.8, "frames": 3})
    assert report["params"]["eps"] == 2.0
    code, out, _ = run_sid(["eval", "fformation", str(tiny), "--scale", "0.01", "--table", "--T", "0.75"], capsys)
    assert code == 0 and out[0].split() == ["dataset", "T", "frames", "precision", "recall", "F1"]
    assert out[1].split() == ["Tiny", "3/4", "3", "1.000", "0.667", "0.800"]


def test_a_dataset_named_pooled_keeps_its_scores_apart_from_the_pooled_ones(tmp_path, capsys):
    # A folder named "pooled" took the key of the scores over every set, and its own row was lost (exit 0).
    truth = {1: [[1, 2]], 2: [[1, 2, 3]], 3: [[4, 5]]}
    folders = [
        str(write_sequence(tmp_path / name, tiny_frames()[:k], truth)) for name, k in (("pooled", 3), ("Tiny", 2))
    ]
    code, out, _ = run_sid(["eval", "fformation", *folders, "--scale", "0.01"], capsys)
    scores = json.loads("\n".join(out))["scores"]
    assert code == 0 and list(scores) == ["pooled-2", "Tiny", "pooled"]
    assert [scores[name]["2/3"]["frames"] for name in scores] == [3, 2, 5]


def test_eval_fformation_tables_keep_their_columns_for_a_long_dataset_name(tmp_path, capsys):
    # The name column was 16 characters wide: a longer folder name pushed its row's numbers out of their columns.
    truth = {1: [[1, 2]], 2: [[1, 2, 3]], 3: [[4, 5]]}
    folders = [
        str(write_sequence(tmp_path / name, tiny_frames(), truth)) for name in ("Tiny", "Poster_session_day_two")
    ]
    for extra in ([], ["--errors"]):
        code, out, _ = run_sid(["eval", "fformation", *folders, "--scale", "0.01", "--table", *extra], capsys)
        assert code == 0
        tables = "\n".join(out).split("\n\n")  # the scores, then with --errors how the groups came out
        assert len(tables) == 1 + len(extra)
        for table in tables:
            assert len({len(line) for line in table.splitlines()}) == 1, table  # every column right-aligned


def test_eval_fformation_counts_how_each_true_group_came_out(tmp_path, capsys):
    tiny = write_sequence(tmp_path / "Tiny", tiny_frames(), {1: [[1, 2]], 2: [[1, 2, 3]], 3: [[4, 5]]})
    code, out, _ = run_sid(["eval", "fformation", str(tiny), "--errors"], capsys)
    assert code == 0
    assert json.loads("\n".join(out))["group_errors"]["Tiny"] == {
        "exact": 2, "one_too_many": 0, "more_too_many": 0, "lacking": 0, "mixed": 0, "missed": 1, "false_groups": 0
    }  # fmt: skip
    code, out, _ = run_sid(["eval", "fformation", str(tiny), "--errors", "--table"], capsys)
    assert code == 0 and out[-2].split()[:4] == ["dataset", "true", "groups", "exact"]
    assert out[-1].split() == ["Tiny", "3", "2", "(67%)", *["0", "(0%)"] * 4, "1", "(33%)", "0"]
    code, _, err = run_sid(["eval", "fformation", str(tiny), "--errors", "--grid", "alone_price=0.5,0.65"], capsys)
    assert code == 2 and "--errors counts one detector's groups" in err


@pytest.mark.parametrize("value", ["-5", "nan", "1e400"])
def test_eval_fformation_names_a_bad_facing_noise_as_typed(tmp_path, capsys, value):
    # It was checked after turning degrees into radians: "-5" came back as "-0.0872... radians".
    tiny = write_sequence(tmp_path / "tiny", tiny_frames(), {1: [[1, 2]]})
    with pytest.raises(SystemExit) as stop:
        main(["eval", "fformation", str(tiny), "--facing-noise", value])
    assert stop.value.code == 2
    assert f"--facing-noise: expected a finite number of degrees >= 0, got '{value}'" in capsys.readouterr().err


def test_eval_fformation_warns_of_people_left_out_without_a_position(tmp_path, capsys):
    frames = tiny_frames()
    frames[0] = np.vstack([frames[0], [7, np.nan, 0.0, 0.0], [8, 0.0, np.inf, 0.0]])
    frames[1] = np.vstack([frames[1], [9, np.nan, np.nan, np.nan]])
    tiny = write_sequence(tmp_path / "Tiny", frames, {1: [[1, 2]], 2: [[1, 2, 3]], 3: [[4, 5]]})
    code, out, err = run_sid(["eval", "fformation", str(tiny)], capsys)
    assert code == 0 and "warning: Tiny: 3 people without a finite position left out (in 2 frames)" in err
    assert json.loads("\n".join(out))["scores"]["Tiny"]["2/3"]["f1"] == pytest.approx(0.8)  # as without them


def test_eval_fformation_warns_of_people_without_a_facing(tmp_path, capsys):
    """A NaN theta (no head pose) made the facing unknown and changed the scores without a word."""
    frames = tiny_frames()
    frames[0][1, 3] = frames[1][0, 3] = frames[1][2, 3] = np.nan
    tiny = write_sequence(tmp_path / "Tiny", frames, {1: [[1, 2]], 2: [[1, 2, 3]], 3: [[4, 5]]})
    code, _, err = run_sid(["eval", "fformation", str(tiny)], capsys)
    assert code == 0 and (
        "warning: Tiny: 3 of 8 people (in 2 frames) have a theta that is not a finite number: their facing is taken "
        "as unknown" in err
    )
    whole = write_sequence(tmp_path / "Whole", tiny_frames(), {1: [[1, 2]]})
    code, _, err = run_sid(["eval", "fformation", str(whole)], capsys)
    assert code == 0 and "theta" not in err


def test_eval_fformation_says_what_finds_no_group_and_facings_in_another_convention(tmp_path, capsys):
    """Silent scores of 0 before: no facing at all, a ground truth that lists no group, compass headings."""
    blind = [np.column_stack([f[:, :3], np.full(len(f), np.nan)]) for f in tiny_frames()]
    folder = write_sequence(tmp_path / "Blind", blind, {1: [[1, 2]], 2: [[1, 2, 3]], 3: [[4, 5]]})
    code, _, err = run_sid(["eval", "fformation", str(folder)], capsys)
    assert code == 0 and "with no facing at all the o-space methods find no group" in err
    code, _, err = run_sid(["eval", "fformation", str(folder), "--positions-only-reach", "1"], capsys)
    assert code == 0 and "taken as unknown" in err and "find no group" not in err
    lonely = write_sequence(tmp_path / "Lonely", tiny_frames(), {1: [[1]], 2: [[3]]})
    code, _, err = run_sid(["eval", "fformation", str(lonely)], capsys)
    assert code == 0 and "no ground-truth group of two or more people in any frame" in err
    compass = [np.column_stack([f[:, :3], math.pi / 2 - f[:, 3]]) for f in tiny_frames()]
    folder = write_sequence(tmp_path / "Compass", compass, {1: [[1, 2]], 2: [[1, 2, 3]], 3: [[4, 5]]})
    code, _, err = run_sid(["eval", "fformation", str(folder)], capsys)
    assert code == 0 and "face their group's centre little (mean cosine" in err
    tiny = write_sequence(tmp_path / "Tiny", tiny_frames(), {1: [[1, 2]], 2: [[1, 2, 3]], 3: [[4, 5]]})
    code, _, err = run_sid(["eval", "fformation", str(tiny)], capsys)
    assert code == 0 and "warning" not in err


def test_eval_fformation_scores_past_ground_truth_frames_without_features(tmp_path, capsys):
    slip = write_sequence(tmp_path / "Slip", tiny_frames(), {1: [[1, 2]], 9: [[4, 5]], 2: [[1, 2, 3]]})
    code, out, err = run_sid(["eval", "fformation", str(slip)], capsys)
    assert code == 0 and "1 ground-truth frame of 3 without a frame in features.mat (first GTtimestamp 9)" in err
    assert json.loads("\n".join(out))["scores"]["Slip"]["2/3"]["frames"] == 2


def test_eval_fformation_reads_the_unit_by_default(tmp_path, capsys):
    """Without --scale the positions' unit is read off the people's spacing: centimetres here, said on stderr."""
    tiny = write_sequence(tmp_path / "Tiny", tiny_frames(), {1: [[1, 2]], 2: [[1, 2, 3]], 3: [[4, 5]]})
    code, out, err = run_sid(["eval", "fformation", str(tiny)], capsys)
    assert code == 0 and "Tiny: positions read as centimetres (--scale 0.01)" in err and "warning" not in err
    assert json.loads("\n".join(out))["scores"]["Tiny"]["2/3"]["f1"] == pytest.approx(0.8)
    metres = [frame * np.array([1, 0.01, 0.01, 1]) for frame in tiny_frames()]
    in_metres = write_sequence(tmp_path / "Metres", metres, {1: [[1, 2]], 2: [[1, 2, 3]], 3: [[4, 5]]})
    code, out, err = run_sid(["eval", "fformation", str(in_metres), str(tiny), "--scale", "auto", "0.01"], capsys)
    assert code == 0 and "positions read as" not in err
    scores = json.loads("\n".join(out))["scores"]
    assert scores["Metres"]["2/3"] == scores["Tiny"]["2/3"]
    code, _, err = run_sid(["eval", "fformation", str(tiny), "--scale", "1"], capsys)  # as asked, with the warning
    assert code == 0 and "look like centimetres, scale 0.01" in err
    with pytest.raises(SystemExit):
        main(["eval", "fformation", str(tiny), "--scale", "-1"])
    assert "expected a positive number or auto" in capsys.readouterr().err


def test_eval_fformation_reads_settings_gc_in_the_positions_units(tmp_path, capsys):
    """A set in metres with its settings_gc.mat in metres (stride 0.45, mdl 3) scores as the same set in
    centimetres (45, 30000): the settings were read as centimetres whatever the positions' unit, recall 0."""
    truth = {1: [[1, 2]], 2: [[1, 2, 3]], 3: [[4, 5]]}
    scores = {}
    for name, factor in (("Centimetres", 1.0), ("Metres", 0.01), ("Millimetres", 10.0)):
        folder = write_sequence(tmp_path / name, [f * [1, factor, factor, 1] for f in tiny_frames()], truth)
        scipy.io.savemat(folder / "settings_gc.mat", {"stride": 45 * factor, "mdl": 30000 * factor**2})
        code, out, _ = run_sid(["eval", "fformation", str(folder), "--gcff-settings"], capsys)
        assert code == 0
        scores[name] = json.loads("\n".join(out))["scores"][name]
    assert scores["Centimetres"]["2/3"]["recall"] > 0
    assert scores["Metres"] == scores["Millimetres"] == scores["Centimetres"]


def test_eval_fformation_scores_the_annotated_sequences_of_a_release_naming_the_others(tmp_path, capsys):
    """An unannotated sequence beside annotated ones was the end of the run; the loader's warnings said "sid eval:"."""
    truth = {1: [[1, 2]], 2: [[1, 2, 3]], 3: [[4, 5]]}
    release = tmp_path / "Release"
    for name in ("Seq1", "Test"):
        write_sequence(release / name, tiny_frames(), truth if name == "Seq1" else {})
        scipy.io.savemat(release / name / "settings_gc.mat", {"stride": 45, "mdl": 30000})
    (release / "Test" / "groundtruth.mat").unlink()
    for options in ([], ["--gcff-settings"]):
        code, out, err = run_sid(["eval", "fformation", str(release), *options], capsys)
        assert code == 0 and json.loads("\n".join(out))["scores"]["Release"]["2/3"]["frames"] == 3
        assert (
            err.count(f"sid eval fformation: warning: fformation: {release}: 1 sequence without groundtruth.mat") == 1
        )


def test_orientation_quality_is_read_and_checked(capsys, monkeypatch):
    # A pair 1.6 m apart, the second looking 120 degrees off: a clear facing is refused, a doubtful one joins.
    people = [{"id": 1, "x": 0.0, "y": 0.0, "theta": 0.0}, {"id": 2, "x": 1.6, "y": 0.0, "theta": math.radians(300)}]
    lines = [
        {"frame": 0, "people": people},
        {"frame": 1, "people": [people[0], people[1] | {"orientation_quality": 0}]},
    ]
    lines.append({"frame": 2, "people": [people[0], people[1] | {"orientation_quality": 1.5}]})
    monkeypatch.setattr(sys, "stdin", io.StringIO("\n".join(json.dumps(line) for line in lines) + "\n"))
    code, out, err = run_sid(["groups", "-"], capsys)
    assert code == 0 and [json.loads(line)["groups"] != [] for line in out] == [False, True]
    assert "line 3: people[1] (id 2): orientation_quality must be a number in [0, 1], got 1.5" in err


def test_eval_fformation_cross_validates_over_a_grid(tmp_path, capsys):
    for name in ("A", "B"):
        write_sequence(tmp_path / name, tiny_frames(), {1: [[1, 2]], 2: [[1, 2, 3]]})
    dirs = [str(tmp_path / "A"), str(tmp_path / "B")]
    code, out, err = run_sid(
        ["eval", "fformation", *dirs, "--scale", "0.01", "--grid", "alone_price=0.01,0.65"], capsys
    )
    report = json.loads("\n".join(out))
    assert code == 0 and [f["chosen"] for f in report["folds"]] == [{"alone_price": 0.65}] * 2
    assert report["grid"][0] == {"alone_price": 0.01, "f1": {"A": 0.0, "B": 0.0}}
    assert "\ncross-validation: 2/2 (100 %)" in "\n" + err  # progress, off a terminal
    args = ["eval", "fformation", *dirs, "--scale", "0.01", "--grid", "alone_price=0.01,0.65", "--workers", "2"]
    code, pooled, _ = run_sid(args, capsys)
    assert code == 0 and pooled == out  # the same report from two worker processes
    code, _, err = run_sid(["eval", "fformation", *dirs, "--scale", "0.01", "--workers", "2"], capsys)
    assert code == 2 and "--workers spreads a cross-validation's grid points: give --cross-validate or --grid" in err
    code, out, _ = run_sid(
        ["eval", "fformation", *dirs, "--scale", "0.01", "--table", "--grid", "group_price=0.65"], capsys
    )
    assert code == 0 and out[-1].startswith("held-out F1 1.000-1.000")
    code, _, err = run_sid(["eval", "fformation", *dirs, "--grid", "stride=1"], capsys)
    assert code == 2 and "numeric fields of GroupParams" in err
    code, out, _ = run_sid(["eval", "fformation", *dirs, "--scale", "0.01", "--cross-validate"], capsys)
    report = json.loads("\n".join(out))
    assert code == 0 and set(report["folds"][0]["chosen"]) == set(DEFAULT_GRID)
    assert len(report["grid"]) == math.prod(len(values) for values in DEFAULT_GRID.values())


@pytest.mark.parametrize(
    ("option", "value", "bad", "message"),
    [("--facing-noise", "20", None, ""), ("--facing-missing", "0.5", "2", "share of facings missing")],
)
def test_eval_fformation_changes_the_facings_seeded(tmp_path, capsys, option, value, bad, message):
    """--facing-noise adds seeded noise to every facing, --facing-missing makes a seeded share of them unknown."""
    tiny = write_sequence(tmp_path / "Tiny", tiny_frames(), {1: [[1, 2]], 2: [[1, 2, 3]]})
    args = ["eval", "fformation", str(tiny), "--scale", "0.01", option]
    first, second = run_sid([*args, value], capsys), run_sid([*args, value], capsys)
    assert first[0] == 0 and first[1] == second[1]
    if bad is not None:  # a bad noise is argparse's to refuse (test_eval_fformation_names_a_bad_facing_noise_as_typed)
        code, _, err = run_sid([*args, bad], capsys)
        assert code == 2 and message in err


def test_eval_fformation_reports_malformed_data(tmp_path, capsys):
    (tmp_path / "Bad").mkdir()
    (tmp_path / "Bad" / "features.mat").write_text("garbage")
    code, _, err = run_sid(["eval", "fformation", str(tmp_path / "Bad")], capsys)
    assert code == 2 and "cannot read" in err and "features.mat" in err
    with pytest.raises(SystemExit):
        main(["eval", "fformation", str(tmp_path / "Bad"), "--T", "3/2"])
    assert "must lie in (1/2, 1]" in capsys.readouterr().err


def test_eval_fformation_on_the_real_datasets(capsys):
    synth = shared_path("data", "fformation", "Synth")
    coffee = shared_path("data", "fformation", "CoffeeBreak")
    code, out, _ = run_sid(["eval", "fformation", str(synth), str(coffee), "--scale", "0.01", "--table"], capsys)
    assert code == 0
    rows = {(line.split()[0], line.split()[1]): float(line.split()[-1]) for line in out[1:]}
    assert set(rows) == {(d, t) for d in ("Synth", "CoffeeBreak", "pooled") for t in ("2/3", "1")}
    assert rows[("Synth", "2/3")] > 0.9


def test_eval_fformation_warns_when_scaled_positions_are_not_metres(tmp_path, capsys):
    tiny = write_sequence(tmp_path / "Tiny", tiny_frames(), {1: [[1, 2]], 2: [[1, 2, 3]], 3: []})
    code, _, err = run_sid(["eval", "fformation", str(tiny), "--scale", "1"], capsys)
    assert code == 0 and "Tiny: scaled by 1, the median distance" in err and "centimetres, scale 0.01" in err
    code, _, err = run_sid(["eval", "fformation", str(tiny), "--scale", "0.01"], capsys)
    assert code == 0 and "warning" not in err
    # One scale per DIR: the second copy, scaled as metres, is warned about by name.
    other = write_sequence(tmp_path / "Other", tiny_frames(), {1: [[1, 2]]})
    code, _, err = run_sid(["eval", "fformation", str(tiny), str(other), "--scale", "0.01", "1"], capsys)
    assert code == 0 and "warning: Other: scaled by 1" in err and "Tiny" not in err
    code, _, err = run_sid(["eval", "fformation", str(tiny), str(other), "--scale", "0.01", "1", "1"], capsys)
    assert code == 2 and "--scale takes one value or one per DIR (2), got 3" in err


def test_eval_fformation_reads_degrees_and_warns_about_truth_ids_it_cannot_find(tmp_path, capsys):
    frames = [np.column_stack([f[:, :3], np.degrees(f[:, 3])]) for f in tiny_frames()]
    folder = write_sequence(tmp_path / "Degrees", frames, {1: [[1, 2]], 2: [[1, 2, 3]], 3: [[5, 6]]})
    code, _, err = run_sid(["eval", "fformation", str(folder), "--scale", "0.01", "--radians"], capsys)
    assert code == 2 and "theta reaches 180, beyond two turns" in err and "--degrees" in err
    code, out, err = run_sid(["eval", "fformation", str(folder), "--scale", "0.01", "--degrees", "--table"], capsys)
    assert code == 0 and out[1].split()[:3] == ["Degrees", "2/3", "3"] and "theta read as" not in err
    assert "Degrees: 1 of the 7 ground-truth group members are not among their frame's people" in err
    for scale in (["--scale", "0.01"], []):  # by default, with the scale given or read off the spacing as well
        code, read, err = run_sid(["eval", "fformation", str(folder), *scale, "--table"], capsys)
        assert code == 0 and read == out and "Degrees: theta read as degrees" in err
    with pytest.raises(SystemExit) as usage:
        run_sid(["eval", "fformation", str(folder), "--degrees", "--radians"], capsys)
    assert usage.value.code == 2 and "--radians: not allowed with argument --degrees" in capsys.readouterr().err


def test_eval_fformation_scores_gcff_with_each_sequences_own_settings(tmp_path, capsys):
    import scipy.io

    for name, stride in (("Seq1", 50), ("Seq2", 20)):
        write_sequence(tmp_path / "Set" / name, tiny_frames(), {1: [[1, 2]], 2: [[1, 2, 3]]})
        scipy.io.savemat(tmp_path / "Set" / name / "settings_gc.mat", {"stride": stride, "mdl": 30000})
    code, out, _ = run_sid(["eval", "fformation", str(tmp_path / "Set"), "--scale", "0.01", "--gcff-settings"], capsys)
    report = json.loads("\n".join(out))
    assert code == 0 and report["params"]["method"] == "gcff" and report["scores"]["Set"]["2/3"]["frames"] == 4
    args = ["eval", "fformation", str(tmp_path / "Set"), str(tmp_path / "Set"), "--gcff-settings", "--cross-validate"]
    code, _, err = run_sid(args, capsys)
    assert code == 2 and "--gcff-settings" in err
    (tmp_path / "Set" / "Seq2" / "settings_gc.mat").unlink()
    code, _, err = run_sid(["eval", "fformation", str(tmp_path / "Set"), "--gcff-settings"], capsys)
    assert code == 2 and "settings_gc.mat is missing" in err


def test_keys_given_twice_and_unknown_fields_are_malformed_lines_as_in_scenario_files(tmp_path, capsys):
    lines = [
        '{"frame": 0, "frame": 1, "people": []}',
        json.dumps({"frame": 1, "people": [{"id": 1, "x": 0.0, "y": 0.0, "thta": 3.1}]}),  # a misspelt facing
        json.dumps({"frame": 2, "people": [], "stamp": 4.0}),
        '{"frame": 3, "people": [{"id": 1, "x": 0.0, "x": 5.0, "y": 0.0}]}',
        json.dumps(PAIR),
    ]
    source = tmp_path / "frames.jsonl"
    source.write_text("\n".join(lines) + "\n")
    code, out, err = run_sid(["groups", str(source)], capsys)
    assert code == 0 and [json.loads(line)["frame"] for line in out] == [0]
    assert err.splitlines() == [
        "sid groups: line 1: not valid JSON (duplicate key 'frame')",
        "sid groups: line 2: people[0]: unknown field 'thta' (the fields are id, x, y, theta, orientation_quality)",
        "sid groups: line 3: unknown field 'stamp' (the fields are frame, people)",
        "sid groups: line 4: not valid JSON (duplicate key 'x')",
        "sid groups: skipped 4 malformed lines",
    ]
    code, out, err = run_sid(["groups", "--strict", str(source)], capsys)
    assert (
        code == 2 and out == [] and err.splitlines() == ["sid groups: line 1: not valid JSON (duplicate key 'frame')"]
    )


def test_a_facing_in_degrees_by_mistake_is_a_malformed_line(tmp_path, capsys):
    """theta 180 read as radians points anywhere (180 rad is 233 degrees): a yaw beyond two turns is refused, naming
    the unit, as sid eval fformation reads such a file as degrees; an unwrapped yaw within two turns is kept."""
    degrees = {
        "frame": 1,
        "people": [{"id": 1, "x": 2.0, "y": 0.0, "theta": 0}, {"id": 2, "x": 2.8, "y": 0.0, "theta": 180}],
    }
    unwrapped = {"frame": 2, "people": [{"id": 1, "x": 2.0, "y": 0.0, "theta": -2 * math.pi}]}
    source = tmp_path / "frames.jsonl"
    source.write_text("".join(json.dumps(line) + "\n" for line in (PAIR, degrees, unwrapped)))
    code, out, err = run_sid(["groups", str(source)], capsys)
    assert code == 0 and [json.loads(line)["frame"] for line in out] == [0, 2]
    assert err.splitlines()[0] == (
        "sid groups: line 2: people[1] (id 2): theta 180 is beyond two turns (4 pi): radians expected, not degrees"
    )


def test_a_json_document_written_over_several_lines_is_named_as_such(tmp_path, capsys):
    """An indented JSON file is not JSON lines: its first line, a lone brace, said 'line 2 column 1 (char 2)' of a
    one-line input; the position is now within the line, and the message says what JSON lines are."""
    source = tmp_path / "frames.json"
    source.write_text(json.dumps(PAIR, indent=2) + "\n")
    code, out, err = run_sid(["groups", "--strict", str(source)], capsys)
    assert code == 2 and out == []
    assert err == (
        "sid groups: line 1: not valid JSON (Expecting property name enclosed in double quotes at the end of the line; "
        "JSON lines hold one whole object per line: is this one JSON document over several lines?)\n"
    )


def _erring_set(tmp_path):
    """Tiny's frames and a fifth: its pair and triangle found exactly, its back-to-back pair missed. Frame 3 (the
    back-to-back pair alone, missed: F1 0 at T = 1) is the worst, frame 5 (F1 0.8) next, frames 1-2 are clean."""
    pair, triangle, back_to_back, _ = tiny_frames()
    far_triangle, far_pair = triangle + [10, 600, 0, 0], back_to_back + [0, 0, 600, 0]
    frames = [*tiny_frames(), np.vstack([pair[:2], far_triangle, far_pair])]
    truth = {1: [[1, 2]], 2: [[1, 2, 3]], 3: [[4, 5]], 5: [[1, 2], [11, 12, 13], [4, 5]]}
    return write_sequence(tmp_path / "Tiny", frames, truth)


def test_eval_fformation_draws_the_frames_with_errors_worst_first(tmp_path, capsys):
    tiny, out_dir = _erring_set(tmp_path), tmp_path / "pictures"
    code, out, err = run_sid(["eval", "fformation", str(tiny), "--errors", "--pictures", str(out_dir)], capsys)
    assert code == 0 and json.loads("\n".join(out))["group_errors"]["Tiny"]["missed"] == 2  # stdout: the report
    assert sorted(p.name for p in out_dir.iterdir()) == ["frame_Tiny_01.png", "frame_Tiny_02.png", "index.csv"]
    index = (out_dir / "index.csv").read_text().splitlines()
    assert [row.split(",")[4] for row in index[1:]] == ["3", "5"]  # timestamps, worst first; frames 1, 2 clean
    assert [row.split(",")[-2:] for row in index[1:]] == [["missed 1", "frame_Tiny_01.png"],
                                                          ["missed 1", "frame_Tiny_02.png"]]  # fmt: skip
    for name in ("frame_Tiny_01.png", "frame_Tiny_02.png"):
        data = (out_dir / name).read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n" and 10_000 < len(data) < 1_000_000
        height, width = cv2.imread(str(out_dir / name)).shape[:2]
        assert 400 < height < 2000 and 600 < width < 2500
    assert "Tiny: 2 frames with errors, 2 drawn" in err and f"wrote {out_dir / 'index.csv'}" in err


def test_eval_fformation_pictures_are_capped_and_a_rerun_replaces_them(tmp_path, capsys):
    tiny, out_dir = _erring_set(tmp_path), tmp_path / "pictures"
    code, _, _ = run_sid(["eval", "fformation", str(tiny), "--pictures", str(out_dir)], capsys)
    assert code == 0 and len(list(out_dir.glob("frame_*.png"))) == 2
    (out_dir / "notes.txt").write_text("mine")
    argv = ["eval", "fformation", str(tiny), "--pictures", str(out_dir), "--pictures-max", "1", "--method", "gcff"]
    code, _, err = run_sid([*argv, "--facing-noise", "20"], capsys)
    assert code == 0 and "Tiny: 2 frames with errors, 1 drawn" in err
    assert sorted(p.name for p in out_dir.iterdir()) == ["frame_Tiny_1.png", "index.csv", "notes.txt"]
    assert len((out_dir / "index.csv").read_text().splitlines()) == 2
    assert (out_dir / "notes.txt").read_text() == "mine"  # not the run's: kept


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--cross-validate"], "--pictures draws one detector's groups: it takes no --grid or --cross-validate"),
        (["--grid", "alone_price=0.5,0.65"], "--pictures draws one detector's groups"),
    ],
)
def test_eval_fformation_refuses_pictures_where_they_make_no_sense(tmp_path, capsys, extra, message):
    tiny, out_dir = _erring_set(tmp_path), tmp_path / "pictures"
    code, out, err = run_sid(["eval", "fformation", str(tiny), str(tiny), "--pictures", str(out_dir), *extra], capsys)
    assert code == 2 and message in err and out == [] and not out_dir.exists()


def test_eval_fformation_refuses_a_picture_cap_without_pictures_and_a_file_for_a_folder(tmp_path, capsys):
    tiny = _erring_set(tmp_path)
    code, _, err = run_sid(["eval", "fformation", str(tiny), "--pictures-max", "3"], capsys)
    assert code == 2 and "--pictures-max caps --pictures: give --pictures DIR too" in err
    (tmp_path / "file").write_text("")
    code, _, err = run_sid(["eval", "fformation", str(tiny), "--pictures", str(tmp_path / "file")], capsys)
    assert code == 2 and "--pictures" in err and "is a file, not a folder" in err

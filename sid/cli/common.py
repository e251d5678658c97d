"""What every ``sid`` subcommand shares: how it reports errors and files, reads JSON lines, writes its output folder
and stops on a signal. The scenario and planner options live in ``sid.cli.planning`` (commands that do not plan never
import OMPL), the group detector's in ``sid.cli.grouping``."""

from __future__ import annotations

import argparse
import contextlib
import fcntl
import fnmatch
import functools
import itertools
import json
import math
import os
import shutil
import signal
import sys
import tempfile
import threading
from collections.abc import Callable, Iterable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from enum import IntEnum
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any, TextIO, cast

from sid.distribution import MissingDependencyError
from sid.documents import TEMPORARY_PREFIX, plural, special_file, unique_keys
from sid.errors import InputError, SidError

if TYPE_CHECKING:  # the pipeline and the sources are imported only by the commands that read frames
    from sid.perception.pipeline import PoseFn

__all__ = [
    "ExitCode",
    "LOCK_NAME",
    "LineHandler",
    "LineTooLong",
    "LinesProcess",
    "MAX_LINE_BYTES",
    "OutputFolderError",
    "OutputFolderInUse",
    "StagedOutput",
    "SYNTHETIC_FRAMES",
    "StandardOutputError",
    "Terminated",
    "add_bag_topic_options",
    "add_output_option",
    "bounded_lines",
    "check_output_folder",
    "clear_owned",
    "exit_code",
    "fail",
    "guarded_standard_output",
    "name_width",
    "output_folder_lock",
    "plain_text",
    "positive_int",
    "positive_number",
    "positive_seconds",
    "pose_model",
    "print_written",
    "process_json_lines",
    "read_json_lines",
    "refuse_unknown_fields",
    "report_standard_output",
    "run_json_lines",
    "signals_as_interrupts",
    "signals_deferred",
    "staged_output",
    "whole_number",
]


class ExitCode(IntEnum):
    """What a ``sid`` command's exit status means (README, "Exit codes"); 128 + N after signal N (130 Ctrl-C, 143
    SIGTERM)."""

    OK = 0
    FAILURE = 1
    """The run failed: a file could not be written, a source stopped, a benchmark failed."""
    USAGE = 2
    """Bad command line or bad input (a file, a line, a value); the message names the problem."""
    NO_PATH = 3
    """The robot's task was not done: no path (an impossible task, or none found in the budget), or in ``sid
    simulate`` the goal not reached (run.json's ``reason`` says why)."""
    MISSING_DEPENDENCY = 4
    """An optional package the command needs is not installed; the message gives the install command."""
    DIFFERENT = 5
    """``sid model quantize`` / ``compare``: the two models' results differ beyond the tolerances (the table says
    where; a quantized file is kept)."""


def exit_code(error: Exception) -> ExitCode:
    """The exit code of a command stopped by ``error``: writing failed (OSError), no path (planner.problem's
    NoPathError), a missing optional dependency, else bad input."""
    if isinstance(error, MissingDependencyError):
        return ExitCode.MISSING_DEPENDENCY
    problem = sys.modules.get("planner.problem")  # not imported here: commands that do not plan never load it
    if problem is not None and isinstance(error, problem.NoPathError):
        return ExitCode.NO_PATH
    if isinstance(error, OSError) and not isinstance(error, OutputFolderInUse):  # a busy folder: choose another
        return ExitCode.FAILURE
    return ExitCode.USAGE


class OutputFolderError(SidError, ValueError):
    """``--out`` names something that cannot be (or become) a writable folder."""


def check_output_folder(path: str | Path, option: str = "--out") -> Path:
    """``path`` as a Path when it is a folder sid can write in, or can be created as one; creates nothing.

    Commands call this before any work, so a run is not spent and then lost on the write. Raises
    OutputFolderError ``"--out PATH: reason"``: the path is empty or blank, a file, a parent of it is a file, or the
    nearest existing folder cannot be written (permissions, a read-only file system).
    """
    if not str(path).strip():  # an unset variable in a script ($OUT): the working folder is not what was meant
        raise OutputFolderError(f"{option} {path!r}: an empty path; give a folder (. for the working folder)")
    folder = existing = Path(path)
    try:
        if "\0" in str(path):
            raise InputError("embedded null byte")
        while not existing.exists() and existing != existing.parent:
            existing = existing.parent  # the nearest existing ancestor: the folder is created in it
    except (OSError, ValueError) as exc:  # a name too long, a parent that cannot be searched
        reason = getattr(exc, "strerror", None) or exc
        raise OutputFolderError(f"{option} {path!r}: not a usable path ({reason})") from None
    writable = existing.is_dir()
    if writable:
        try:
            with tempfile.TemporaryFile(dir=existing):
                pass
        except OSError as exc:  # permissions, a read-only file system
            where = "in the folder" if existing == folder else f"in {existing} to create the folder"
            raise OutputFolderError(f"{option} {path}: cannot write {where} ({exc.strerror or exc})") from None
    if not writable:
        reason = "is a file, not a folder" if existing == folder else f"cannot create the folder, {existing} is a file"
        raise OutputFolderError(f"{option} {path}: {reason}")
    return folder


def add_output_option(parser: argparse.ArgumentParser, command: str, what: str) -> None:
    """``--out DIR``, by default ``./sid-COMMAND`` (every command that writes files has one), for ``what``."""
    parser.add_argument(
        "--out",
        default=f"sid-{command}",
        metavar="DIR",
        help=f"output folder for {what}, created if missing (default: ./%(default)s)",
    )


def plain_text(doc: str) -> str:
    """A docstring as ``--help`` text: without the backquotes of its literals (reStructuredText or Markdown)."""
    return doc.replace("`", "")


def name_width(names: Iterable[str], least: int = 16) -> int:
    """Width of a table's first column: the longest of ``names`` (datasets are named by their folders), at least
    ``least`` characters, so that a long name does not push its row's numbers out of their columns."""
    return max([least, *(len(name) for name in names)])


def whole_number(low: int) -> Callable[[str], int]:
    """argparse type: a whole number >= ``low``."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            value = low - 1
        if value < low:
            raise argparse.ArgumentTypeError(f"expected a whole number >= {low}, got {text!r}")
        return value

    return parse


positive_int = whole_number(1)
"""argparse type: a whole number >= 1."""


def positive_number(what: str, *, zero: bool = False) -> Callable[[str], float]:
    """argparse type: a finite number above 0 (with ``zero``, 0 or above); ``what`` names it in the error
    ("expected a positive WHAT", or "a finite WHAT >= 0")."""
    expected = f"a finite {what} >= 0" if zero else f"a positive {what}"

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not (math.isfinite(value) and (value >= 0 if zero else value > 0)):
            raise argparse.ArgumentTypeError(f"expected {expected}, got {text!r}")
        return value

    return parse


positive_seconds = positive_number("number of seconds")
"""argparse type of a time budget (refused before any output: a budget of nan was printed in the first progress line
before the planner refused it)."""


def fail(command: str, error: Exception) -> int:
    """Print ``command: error`` on stderr; its ``exit_code``."""
    print(f"{command}: {error}", file=sys.stderr)
    return exit_code(error)


LineHandler = Callable[[Any, Callable[[str], None]], dict[str, Any]]
"""What a JSON-lines command does with one parsed line: the JSON object it writes for it; ValueError for a bad line.
Its second argument notes something about a good line on stderr (``COMMAND: line N: note: TEXT``)."""


MAX_LINE_BYTES = 16 * 1024**2
"""The longest line ``sid groups`` and ``sid track`` read (a line of 100 people with keypoints is about 100 kB):
input with no newline in sight (``/dev/zero`` on stdin, a binary file) ends the run there, not in memory."""


class LineTooLong(SidError, ValueError):
    """A JSON-lines input whose line has no newline within ``MAX_LINE_BYTES``: the rest cannot be read as lines."""


def bounded_lines(stream: IO[Any]) -> Iterator[str | bytes]:
    """The lines of ``stream`` (bytes or text) as ``readline`` gives them, each read with a bound: LineTooLong for
    one longer than ``MAX_LINE_BYTES``."""
    for number in itertools.count(1):
        line = stream.readline(MAX_LINE_BYTES + 1)
        if not line:
            return
        if len(line) > MAX_LINE_BYTES and line[-1:] not in ("\n", b"\n"):
            raise LineTooLong(
                f"line {number} is longer than {MAX_LINE_BYTES:,} bytes (no newline): not JSON lines; stopped there"
            )
        yield line


LinesProcess = Callable[[Iterable[str | bytes], TextIO, TextIO], int]
"""A JSON-lines command's work on its input lines, its output and its error stream (a ``process_json_lines`` call
with the command's handler): the exit code."""


def run_json_lines(command: str, file: str, process: LinesProcess) -> int:
    """``process`` on the lines of ``file`` read as bytes (``-``: stdin), writing to stdout and stderr; its exit code,
    or 2 when ``file`` cannot be read: a device or a folder (a FIFO is read as a stream), a line longer than
    ``MAX_LINE_BYTES``. A failing stdout raises ``StandardOutputError`` (``sid.cli.main`` reports it)."""
    special = None if file == "-" else special_file(file, streams=True)  # a FIFO is read line by line
    if special:
        print(f"{command}: cannot read {file}: {special}", file=sys.stderr)
        return 2
    try:
        # Bytes, decoded line by line: a line that is not UTF-8 is reported and skipped like any malformed line.
        if file == "-":
            stream: IO[Any] = getattr(sys.stdin, "buffer", sys.stdin)
        else:
            stream = open(file, "rb")  # noqa: SIM115
    except OSError as exc:
        print(f"{command}: cannot read {file}: {exc.strerror}", file=sys.stderr)
        return 2
    with stream:
        try:
            return process(bounded_lines(stream), sys.stdout, sys.stderr)
        except LineTooLong as exc:
            print(f"{command}: {'stdin' if file == '-' else file}: {exc}", file=sys.stderr)
            return 2
        except OSError as exc:  # e.g. the disk fails mid-read (stdout: StandardOutputError)
            print(f"{command}: cannot read {file}: {exc.strerror or exc}", file=sys.stderr)
            return 2


def process_json_lines(
    command: str,
    lines: Iterable[str | bytes],
    out: TextIO,
    err: TextIO,
    handle: LineHandler,
    *,
    strict: bool = False,
) -> int:
    """Write ``handle(value)`` on ``out`` as one JSON line, flushed, for each non-blank line of ``lines``
    (``read_json_lines``). A line that cannot be read, or that ``handle`` refuses (ValueError), is reported on ``err``
    as ``COMMAND: line N: problem`` and skipped, or, with ``strict``, ends the run: exit code 2 (bad input); a note
    ``handle`` makes on a good line as ``COMMAND: line N: note: text``. Returns the exit code: 2 also when lines were
    read and none was good (nothing written: input of another kind, which a script must not take for an empty
    result), 0 otherwise (an empty input too)."""
    skipped = written = 0
    for number, value, problem in read_json_lines(lines):
        if problem is None:
            try:
                record = handle(value, functools.partial(_note, command, number, err))
            except ValueError as exc:
                problem = str(exc)
        if problem is not None:
            print(f"{command}: line {number}: {problem}", file=err, flush=True)
            if strict:
                return ExitCode.USAGE
            skipped += 1
            continue
        out.write(json.dumps(record) + "\n")
        out.flush()
        written += 1
    if skipped:
        none = ", and no line was good" if not written else ""
        print(f"{command}: skipped {plural(skipped, 'malformed line')}{none}", file=err, flush=True)
    return ExitCode.USAGE if skipped and not written else 0


def _note(command: str, number: int, err: TextIO, text: str) -> None:
    """A note on line ``number`` of a JSON-lines input, on ``err``."""
    print(f"{command}: line {number}: note: {text}", file=err, flush=True)


def read_json_lines(lines: Iterable[str | bytes]) -> Iterator[tuple[int, Any, str | None]]:
    """(line number, parsed value, None) for each non-blank line, or (line number, None, problem) for one that is not
    UTF-8 text or not JSON. Bytes are decoded here line by line as UTF-8 (a byte-order mark before the first line is
    dropped); NaN and Infinity are refused, and an object giving a key twice (as scenario files refuse it)."""
    for number, raw in enumerate(lines, start=1):
        if isinstance(raw, bytes):
            try:
                line = raw.decode("utf-8")
            except UnicodeDecodeError as exc:
                if number == 1 and raw[:2] in (b"\xff\xfe", b"\xfe\xff"):
                    yield number, None, "not UTF-8 text (it starts with a UTF-16 byte-order mark; save it as UTF-8)"
                else:
                    yield (
                        number,
                        None,
                        f"not UTF-8 text (byte 0x{raw[exc.start]:02x} at byte {exc.start + 1} of the line)",
                    )
                continue
        else:
            line = raw
        if number == 1:
            line = line.removeprefix("\ufeff")  # a byte-order mark (some Windows editors write one)
        if not line.strip():
            continue
        try:
            value = json.loads(line, parse_constant=_reject_constant, object_pairs_hook=unique_keys)
        except json.JSONDecodeError as exc:  # its "line 2 column 1" would count lines within this one line
            text = line.rstrip()
            where = "the end of the line" if exc.pos >= len(text) else f"character {exc.pos + 1} of the line"
            if text.strip() in ("{", "["):  # the first line of an indented JSON document
                where += "; JSON lines hold one whole object per line: is this one JSON document over several lines?"
            yield number, None, f"not valid JSON ({exc.msg} at {where})"
            continue
        except ValueError as exc:  # NaN or Infinity, a duplicate key
            yield number, None, f"not valid JSON ({exc})"
            continue
        except RecursionError:
            yield number, None, "not valid JSON (nested too deeply)"
            continue
        yield number, value, None


def _reject_constant(name: str) -> float:
    raise InputError(f"{name} is not a number")


def refuse_unknown_fields(data: dict[str, Any], known: tuple[str, ...], prefix: str = "") -> None:
    """ValueError naming the first key of a JSON line's object ``data`` not in ``known``, as scenario files refuse
    one (a misspelt ``thta`` would otherwise be read as an unknown facing)."""
    unknown = [key for key in data if key not in known]
    if unknown:
        raise InputError(f"{prefix}unknown field {unknown[0]!r} (the fields are {', '.join(known)})")


class StandardOutputError(SidError):
    """Standard output cannot be written: it is closed, full (ENOSPC, e.g. ``> /dev/full``) or its reader went away
    (a broken pipe, e.g. ``| head -1``). Not an OSError, so that a command's handler for its own files does not
    take it for one of them; ``sid.cli.main`` reports it (``report_standard_output``)."""

    def __init__(self, error: OSError | None) -> None:
        super().__init__("it is closed" if error is None else (error.strerror or str(error)))
        self.broken_pipe = isinstance(error, BrokenPipeError)


class _GuardedOutput:
    """Standard output (``stream``, None when the process started with it closed) whose write and flush errors
    become ``StandardOutputError``; every other attribute is the stream's."""

    def __init__(self, stream: TextIO | None) -> None:
        self._stream = stream

    def write(self, text: str) -> int:
        if self._stream is None:
            raise StandardOutputError(None)
        try:
            return self._stream.write(text)
        except OSError as exc:
            raise StandardOutputError(exc) from None

    def flush(self) -> None:
        if self._stream is None:
            return
        try:
            self._stream.flush()
        except OSError as exc:
            raise StandardOutputError(exc) from None

    def __getattr__(self, name: str) -> Any:
        if self._stream is None:
            raise StandardOutputError(None)
        return getattr(self._stream, name)


@contextmanager
def guarded_standard_output() -> Iterator[None]:
    """While a command runs, writing to ``sys.stdout`` raises ``StandardOutputError`` when it fails, whatever the
    command was doing; the previous ``sys.stdout`` comes back afterwards."""
    previous = sys.stdout
    sys.stdout = cast(TextIO, _GuardedOutput(previous))
    try:
        yield
    finally:
        sys.stdout = previous


def report_standard_output(command: str, error: StandardOutputError) -> int:
    """The exit code of a run whose standard output failed: 0, quietly, when its reader went away (a broken pipe, as
    Unix tools do), else 1 (a failed run) with ``COMMAND: cannot write standard output (REASON)``. Standard output is
    pointed at /dev/null, so that Python's flush at exit does not fail a second time."""
    if sys.__stdout__ is not None:  # None: closed from the start, then Python does not flush it
        with contextlib.suppress(OSError, ValueError):  # not a file descriptor (e.g. a test's capture)
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.__stdout__.fileno())
    if error.broken_pipe:
        return 0
    print(f"{command}: cannot write standard output ({error})", file=sys.stderr)
    return ExitCode.FAILURE


def print_written(paths: Iterable[object]) -> None:
    """One ``wrote PATH`` line per file written."""
    for path in paths:
        print(f"wrote {path}")


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised in the main thread like Ctrl-C so that the same clean-up runs (exit 128 + 15)."""

    signal_number = signal.SIGTERM


def _terminate(signum: int, frame: object) -> None:
    # The run is stopping: a second SIGTERM (timeout(1) sends one to the process and one to its group) is ignored,
    # not raised inside the clean-up of the first or the "interrupted" line (a traceback).
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    raise Terminated()


@contextmanager
def signals_as_interrupts() -> Iterator[None]:
    """While a command runs, SIGTERM raises ``Terminated`` (a KeyboardInterrupt), as SIGINT raises
    KeyboardInterrupt, once: later SIGTERMs are ignored; the previous handler comes back afterwards. Only the main
    thread can install handlers: in another one (a command run from a worker thread) this does nothing."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, _terminate)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


@contextmanager
def signals_deferred() -> Iterator[None]:
    """SIGINT and SIGTERM held back while a set of files is moved into place, then delivered, so an interruption
    lands before or after the whole set, never inside it (e.g. an overlay without its top view).

    Python runs signal handlers in the main thread whichever thread the signal reached (a worker reading ahead,
    onnxruntime's pool), so the handlers are swapped for one that notes the signal; blocking the signals in this
    thread alone let another thread take them and the handler raise inside the set. In another thread (a command
    run from a worker, where no handler can be set) this does nothing, and a signal whose handler was installed
    outside Python (which Python could not put back) is left alone."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    held: list[int] = []

    def hold(signum: int, frame: object) -> None:
        if signum not in held:
            held.append(signum)

    swapped = [number for number in (signal.SIGINT, signal.SIGTERM) if signal.getsignal(number) is not None]
    previous = {number: signal.signal(number, hold) for number in swapped}
    try:
        yield
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)
        for signum in held:
            signal.raise_signal(signum)  # to the handler restored: raises after the set, as it would have


def clear_owned(folder: Path, owned: Sequence[str], keep: Iterable[str] = ()) -> list[Path]:
    """Delete the files in ``folder`` whose names match a pattern of ``owned`` (what a command writes, e.g.
    ``overlay_*.png``) and are not in ``keep``, and temporary files a killed run left; never anything else.
    Returns the deleted files."""
    kept = set(keep)
    removed = []
    for entry in sorted(folder.iterdir()) if folder.is_dir() else []:
        if entry.name in kept:
            continue
        partial = entry.name.startswith(TEMPORARY_PREFIX)
        ours = any(fnmatch.fnmatchcase(entry.name, pattern) for pattern in owned)
        if partial and entry.is_dir():
            shutil.rmtree(entry, ignore_errors=True)
            removed.append(entry)
        elif (partial or ours) and entry.is_file():
            entry.unlink()
            removed.append(entry)
    return removed


LOCK_NAME = ".sid-lock"
"""The lock file a run holds in its output folder while it writes there (``output_folder_lock``)."""


class OutputFolderInUse(SidError, OSError):
    """Another sid run holds the output folder's lock; the message names the folder and that run's pid."""


@contextmanager
def output_folder_lock(folder: str | Path) -> Iterator[Path]:
    """Hold ``folder``'s lock (``flock`` on ``LOCK_NAME`` in it; the folder is created if missing) while a run
    writes there, so that two runs into one folder never delete or mix each other's files: a second run gets
    ``OutputFolderInUse`` at once. The kernel releases the lock when the process ends, even on SIGKILL; the file is
    deleted when the run ends. Yields the folder."""
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    path = out / LOCK_NAME
    while True:
        handle = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.read(handle, 64).decode("ascii", "replace").strip() or "its pid unknown"
            os.close(handle)
            raise OutputFolderInUse(
                f"{out}: another sid run is writing in this folder ({holder}); wait for it to end or choose another "
                "folder"
            ) from None
        try:
            current = os.stat(path).st_ino == os.fstat(handle).st_ino
        except FileNotFoundError:
            current = False
        if current:
            break
        os.close(handle)  # the run that held it deleted it meanwhile: lock the file that is there now
    try:
        with contextlib.suppress(OSError):  # the pid only words a second run's message (a full disk may refuse it)
            os.ftruncate(handle, 0)
            os.write(handle, f"pid {os.getpid()}".encode())
        yield out
    finally:
        with contextlib.suppress(OSError):
            path.unlink()  # while still held: a run waiting on this file sees it is gone and locks a new one
        os.close(handle)


@dataclass(frozen=True)
class StagedOutput:
    """A temporary folder (``path``) inside the output folder (``folder``) that a command writes its files into."""

    folder: Path
    path: Path

    def final(self, written: str | Path) -> Path:
        """Where a file written under ``path`` ends up in ``folder``."""
        return self.folder / Path(written).relative_to(self.path)


@contextmanager
def staged_output(folder: str | Path, owned: Sequence[str]) -> Iterator[StagedOutput]:
    """Write a command's files whole, as one set: the command writes into a temporary folder inside ``folder``
    (created if missing); when it finishes, the files it wrote replace those of an earlier run (``os.replace``
    each, signals deferred), and files of ``owned`` patterns an earlier run left but this one did not write are
    deleted. When it fails or is interrupted, ``folder`` keeps the earlier run's files and the temporary folder goes.
    The folder's lock is held throughout (``output_folder_lock``: OutputFolderInUse while another run writes there).
    """
    with output_folder_lock(folder) as out:
        staged = StagedOutput(out, Path(tempfile.mkdtemp(prefix=TEMPORARY_PREFIX, dir=out)))
        try:
            yield staged
            written = sorted(p for p in staged.path.rglob("*") if p.is_file())
            with signals_deferred():
                for path in written:
                    target = staged.final(path)
                    target.parent.mkdir(parents=True, exist_ok=True)
                    os.replace(path, target)
                clear_owned(out, owned, keep={p.name for p in written} | {staged.path.name})
        finally:
            shutil.rmtree(staged.path, ignore_errors=True)


def add_bag_topic_options(parser: argparse.ArgumentParser) -> None:
    """``--color-topic``, ``--depth-topic`` and ``--info-topic``: the topics of a rosbag2 ``--source``
    (``sid.sources.BAG_TOPICS``; default: realsense2_camera's names, found under any namespace)."""
    for name, what in (
        ("color", "colour sensor_msgs/Image"),
        ("depth", "depth Image aligned to colour"),
        ("info", "colour CameraInfo"),
    ):
        parser.add_argument(
            f"--{name}-topic",
            metavar="TOPIC",
            help=f"rosbag2 sources: the {what} topic (default: realsense2_camera's, under any namespace)",
        )


SYNTHETIC_FRAMES = 30
"""Frames of a ``synthetic:SCENE`` source in ``sid detect`` (unless --frames) and, per source, in ``sid model``."""


def pose_model(model: Path | None, source: str | None, **load: Any) -> PoseFn:
    """The pose function frames of ``source`` (a source spec; None: camera topics) are run through: the pose model
    ``model`` (an .onnx file, loaded with the ``load`` options of ``load_pose_estimator``), else, for a
    ``synthetic:SCENE`` source, its people's true poses (``TruthPose``), when no ``load`` option is given (else
    ValueError: they would be ignored). SourceError when neither applies."""
    if model is not None:
        from sid.perception.pipeline import image_pose
        from sid.perception.pose import load_pose_estimator
        from sid.perception.pose.session import quiet_load_warnings

        quiet_load_warnings()
        return image_pose(load_pose_estimator(model, **load))
    if source is not None and source.startswith("synthetic:"):
        from sid.synthetic.pose import TruthPose

        options = {"threads": "--threads", "providers": "--provider", "contract": "--contract"}
        given = [options.get(name, name) for name, value in load.items() if value not in (None, "auto")]
        if given:  # they set up a model's session: without a model they would be ignored in silence
            raise InputError(
                f"{', '.join(given)}: an option of the pose model's session, and there is no --model (the synthetic "
                "source's true poses stand in for one); give --model to run a model"
            )
        return TruthPose()
    from sid.sources import SourceError

    scene = source is not None and Path(source).suffix.lower() in (".json", ".yaml", ".yml")
    hint = f"; for a synthetic camera in the scene file, --source synthetic:{source}" if scene else ""
    raise SourceError(f"a real source needs a pose model: --model FILE.onnx (see docs/models.md){hint}")

"""The robustness table of docs/robustness.md: per input kind, the cases tried, how many were accepted or refused
with a clear error, tracebacks, hangs and the peak memory (RSS) of the process that ran them.

    python -m tests.fuzz.robustness_table --cases 300

Each kind runs in its own process (the fuzzed readers with the strategies of tests/fuzz, each case under the hang
alarm of ``tests.fuzz.guards``); the malformed fixtures run as ``sid`` commands, one process each, and their row's
memory is the largest of them (``os.wait4``'s ``ru_maxrss``).
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from collections import Counter
from collections.abc import Callable
from pathlib import Path
from typing import Any

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.conftest import REPO_ROOT
from tests.fuzz.guards import Hang, bounded

MALFORMED = REPO_ROOT / "tests" / "fixtures" / "malformed"


def _scenario(data: Any) -> str:
    from sid.scenario.loader import ScenarioError, load_scenario

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "fuzz.json"
        path.write_text(json.dumps(data))
        try:
            load_scenario(path)
        except ScenarioError:
            return "clear"
    return "accepted"


def _document(case: tuple[bytes, str]) -> str:
    from sid.documents import load_document

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / f"doc{case[1]}"
        path.write_bytes(case[0])
        try:
            load_document(path)
        except ValueError as exc:
            return "clear" if str(exc).startswith(str(path)) else "unclear"
    return "accepted"


def _map(case: tuple[dict, bytes]) -> str:
    from costmap.mapfile import MapFileError, read_map

    with tempfile.TemporaryDirectory() as folder:
        (Path(folder) / "map.pgm").write_bytes(case[1])
        (Path(folder) / "map.yaml").write_text(json.dumps(case[0]))
        try:
            read_map(Path(folder) / "map.yaml")
        except MapFileError:
            return "clear"
    return "accepted"


def _calibration(changes: dict) -> str:
    from sid.perception.camera import Calibration
    from tests.fuzz.test_readers import CALIBRATION

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "calibration.json"
        path.write_text(json.dumps(CALIBRATION | changes))
        try:
            Calibration.from_json(path)
        except ValueError as exc:
            return "clear" if str(path) in str(exc) else "unclear"
    return "accepted"


def _lines(lines: list[bytes]) -> str:
    from sid.cli.groups import process
    from sid.perception.groups import GroupParams

    err = io.StringIO()
    process([line + b"\n" for line in lines], io.StringIO(), err, GroupParams())
    return "clear" if "line " in err.getvalue() else "accepted"


def _mat(case: tuple[bytes, str]) -> str:
    from sid.experiments.fformation import load_dataset

    with tempfile.TemporaryDirectory() as folder:
        (Path(folder) / case[1]).write_bytes(case[0])
        try:
            load_dataset(folder)
        except ValueError:
            return "clear"
    return "accepted"


def _arguments(argv: list[str]) -> str:
    from sid.cli import build_parser

    with contextlib.redirect_stderr(io.StringIO()), contextlib.redirect_stdout(io.StringIO()):
        try:
            build_parser().parse_args(argv)
        except SystemExit as exc:
            return "clear" if exc.code == 2 else "unclear"
    return "accepted"


def _kinds() -> dict[str, tuple[str, Callable[[Any], str], Any]]:
    from tests.fuzz import test_arguments as arguments
    from tests.fuzz import test_input_kinds as kinds
    from tests.fuzz import test_readers as readers

    return {
        "scenario": ("scenario files (JSON fields replaced)", _scenario, readers.mutated_scenarios()),
        "document": (
            "any bytes as a JSON / YAML file",
            _document,
            st.tuples(st.binary(max_size=200), st.sampled_from([".json", ".yaml"])),
        ),  # fmt: skip
        "map": ("map YAML + image (any header size)", _map, readers.map_files()),
        "calibration": (
            "calibration JSON",
            _calibration,
            st.dictionaries(
                st.sampled_from([*readers.CALIBRATION, "color", "depth", "depth_to_color", "depth_scale"]),
                readers.VALUES,
                max_size=4,
            ),
        ),  # fmt: skip
        "lines": ("JSON lines (sid groups)", _lines, readers.LINES),
        "mat": (
            ".mat files (F-formation)",
            _mat,
            st.tuples(st.binary(max_size=300), st.sampled_from(["features.mat", "groundtruth.mat"])),
        ),  # fmt: skip
        "arguments": ("command lines (every command)", _arguments, arguments.command_lines()),
        "keyed_groups": (
            "JSON lines, keys repeated / misspelt (sid groups)",
            kinds.check_groups_lines,
            kinds.groups_lines(),
        ),
        "keyed_track": (
            "JSON lines, keys repeated / misspelt (sid track)",
            kinds.check_track_lines,
            kinds.track_lines(),
        ),
        "scenario_yaml": ("scenario YAML edited as text", kinds.check_scenario_yaml, kinds.scenario_yaml()),
        "pgm": ("PGM maps (comments, any maximum)", kinds.check_pgm, kinds.PGM_CASES),
        "fformation": (".mat files of any cells (F-formation)", kinds.check_fformation, kinds.fformation_sets()),
        "folder": ("frame folders (names, suffixes, pixels)", kinds.check_frame_folder, kinds.frame_folders()),
        "bag": ("rosbag2 recordings (fields, cut messages)", kinds.check_camera_bag, kinds.camera_bags()),
    }


def run_kind(name: str, cases: int) -> dict[str, Any]:
    """Fuzz one kind in this process; its counts and the process's peak RSS (MB)."""
    _, check, strategy = _kinds()[name]
    counts: Counter[str] = Counter()
    examples: dict[str, str] = {}

    @settings(
        max_examples=cases, database=None, derandomize=True, deadline=None, suppress_health_check=list(HealthCheck)
    )
    @given(strategy)
    def fuzz(case: Any) -> None:
        try:
            with bounded():
                outcome = check(case)
        except Hang:
            outcome = "hang"
        except Exception as exc:  # the count this table exists for: must stay 0
            outcome = "traceback"
            examples.setdefault(outcome, f"{type(exc).__name__}: {exc}"[:200])
        counts[outcome] += 1

    started = time.perf_counter()
    fuzz()
    seconds = time.perf_counter() - started
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    return {"kind": name, "counts": dict(counts), "examples": examples, "peak_mb": peak, "seconds": seconds}


def run_fixtures() -> dict[str, Any]:
    """Every malformed fixture through its ``sid`` command, one process each."""
    runs = [["costmap", str(p), "--out", "{out}"] for p in sorted((MALFORMED / "scenario").iterdir())]
    runs += [["groups", str(p)] for p in sorted((MALFORMED / "groups").iterdir())]
    counts: Counter[str] = Counter()
    peak = 0.0
    started = time.perf_counter()
    code = "import sys; from sid.cli import main; sys.exit(main(sys.argv[1:]))"
    for argv in runs:
        with tempfile.TemporaryDirectory() as folder:
            words = [word.replace("{out}", str(Path(folder) / "out")) for word in argv]
            process = subprocess.Popen(
                [sys.executable, "-c", code, *words], cwd=REPO_ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE
            )
            try:
                _, err = process.communicate(timeout=120)
            except subprocess.TimeoutExpired:
                process.kill()
                counts["hang"] += 1
                continue
            finally:
                if process.poll() is None:
                    process.kill()
        # communicate() has reaped the child; its peak RSS is that of the largest child waited for so far.
        peak = max(peak, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024)
        text = err.decode()
        if "Traceback" in text:
            counts["traceback"] += 1
        elif process.returncode == 2 or (argv[0] == "groups" and "line 1:" in text):
            counts["clear"] += 1
        else:
            counts["unclear"] += 1
    seconds = time.perf_counter() - started
    return {"kind": "fixtures", "counts": dict(counts), "examples": {}, "peak_mb": peak, "seconds": seconds}


TITLES = {"fixtures": "malformed fixtures via `sid costmap` / `sid groups`"}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cases", type=int, default=300, help="cases per fuzzed kind (default %(default)s)")
    parser.add_argument("--only", nargs="+", metavar="KIND", help=f"these kinds alone: {', '.join(_kinds())}")
    parser.add_argument("--kind", help=argparse.SUPPRESS)  # internal: run one kind in this process
    args = parser.parse_args()
    if args.kind:
        print(json.dumps(run_kind(args.kind, args.cases)))
        return
    rows = []
    for name in args.only or _kinds():
        out = subprocess.run(
            [sys.executable, "-m", "tests.fuzz.robustness_table", "--kind", name, "--cases", str(args.cases)],
            cwd=REPO_ROOT, capture_output=True, text=True, check=True, env=os.environ | {"PYTHONPATH": str(REPO_ROOT)},
        )  # fmt: skip
        rows.append(json.loads(out.stdout.splitlines()[-1]))
    if not args.only:
        rows.append(run_fixtures())
    titles = {name: title for name, (title, _, _) in _kinds().items()} | TITLES
    print("| input kind | cases | accepted | clear errors | tracebacks | hangs | peak memory (RSS) | time |")
    print("|---|---|---|---|---|---|---|---|")
    for row in rows:
        c = row["counts"]
        tried = sum(c.values())
        print(
            f"| {titles[row['kind']]} | {tried} | {c.get('accepted', 0)} | {c.get('clear', 0)} | "
            f"{c.get('traceback', 0) + c.get('unclear', 0)} | {c.get('hang', 0)} | {row['peak_mb']:.0f} MB | "
            f"{row['seconds']:.0f} s |"
        )
        for outcome, example in row["examples"].items():
            print(f"<!-- {row['kind']} {outcome}: {example} -->")


if __name__ == "__main__":
    main()

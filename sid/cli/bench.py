"""``sid bench [--out DIR] [--quick] [--compare OLD.json] [--only PATTERN]``: time the stages side by side in one
run and write DIR/bench.json and DIR/bench.md (see docs/benchmarks.md)."""

from __future__ import annotations

import argparse
import os
import sys
from dataclasses import asdict
from pathlib import Path

from sid.cli.common import (
    ExitCode,
    add_output_option,
    check_output_folder,
    fail,
    plain_text,
    positive_int,
    staged_output,
)
from sid.distribution import MissingDependencyError
from sid.documents import plural
from sid.experiments.bench import (
    FULL,
    QUICK,
    Context,
    benchmarks,
    format_comparison,
    load_report,
    machine_info,
    markdown,
    run_suite,
    select,
    write_report,
)
from sid.experiments.bench.report import build_report
from sid.perception.pose.session import PROVIDER_CHOICES, check_threads, quiet_load_warnings, resolve_providers

__all__ = ["SHARED_ENV", "add_parser", "default_shared", "find_repository", "repository", "run"]

PLAN_RUNS_FULL, PLAN_RUNS_QUICK = 5, 1
SHARED_ENV = "SID_SHARED"
"""The environment variable naming the folder with models/ and data/ (``--shared``'s default when set)."""


def find_repository(start: Path) -> Path | None:
    """The sid source checkout holding ``start``: it or its nearest parent with pyproject.toml and sid/, or None."""
    for folder in (start, *start.parents):
        if (folder / "pyproject.toml").is_file() and (folder / "sid" / "__init__.py").is_file():
            return folder
    return None


def repository() -> Path | None:
    """The sid checkout this module runs from (a source or editable install), else the one holding the current
    directory (after ``pip install .`` the module lives in site-packages), else None."""
    return find_repository(Path(__file__).resolve().parent) or find_repository(Path.cwd().resolve())


def default_shared() -> Path:
    """``--shared``'s default: $SID_SHARED; else ../shared next to ``repository()``; else ../shared from the
    current directory."""
    if os.environ.get(SHARED_ENV):
        return Path(os.environ[SHARED_ENV])
    repo = repository()
    return (repo.parent if repo is not None else Path.cwd().resolve().parent) / "shared"


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "bench",
        help="time grouping, alignment, lifting, pose models, the per-frame pipeline, costmap and planners",
        description=plain_text(__doc__),
    )
    add_output_option(parser, "bench", "bench.json and bench.md")
    parser.add_argument(
        "--quick", action="store_true", help="few repeats (~0.15 s per stage, 1 planner seed): a smoke run"
    )
    parser.add_argument("--compare", metavar="OLD.json", help="an earlier bench.json: print the change per stage")
    parser.add_argument(
        "--only",
        metavar="PATTERN",
        help="comma-separated stage names or globs, e.g. 'group,align/*' ('group' means group/...); "
        "the stages a ratio refers to run too",
    )
    parser.add_argument("--list", action="store_true", help="list the benchmarks and exit")
    parser.add_argument(
        "--threads",
        type=positive_int,
        default=None,
        metavar="N",
        help="pose model threads, as sid detect --threads (default: the physical cores this process may use)",
    )
    parser.add_argument(
        "--provider",
        choices=PROVIDER_CHOICES,
        default="auto",
        help="pose models' execution provider, as sid detect --provider (default: %(default)s)",
    )
    parser.add_argument(
        "--shared",
        type=Path,
        default=default_shared(),
        help=f"folder with models/ (pose models) and data/ (default: ${SHARED_ENV} when set, else ../shared next to "
        "the sid repository, the one sid runs from or the one holding the current directory; here %(default)s)",
    )
    parser.set_defaults(func=run)


def _progress(index: int, total: int, name: str, status: str) -> None:
    if status:
        print(f"[{index + 1:>2}/{total}] {name}: {status}", file=sys.stderr, flush=True)
    else:
        print(f"[{index + 1:>2}/{total}] {name} ...", file=sys.stderr, flush=True)


def run(args: argparse.Namespace) -> int:
    quiet_load_warnings()  # the pose stages load models: onnxruntime's load-time warnings are noise here
    try:
        old = load_report(args.compare) if args.compare else None
        check_threads(args.threads)  # as sid detect: before the run, not at each pose stage
        resolve_providers(args.provider)
    except MissingDependencyError as exc:  # --provider openvino without it
        return fail("sid bench", exc)
    except ValueError as exc:
        print(f"sid bench: {exc}", file=sys.stderr)
        return 2
    settings = QUICK if args.quick else FULL
    ctx = Context(
        settings,
        args.shared,
        PLAN_RUNS_QUICK if args.quick else PLAN_RUNS_FULL,
        pose_threads=args.threads,
        pose_provider=args.provider,
    )
    items = benchmarks(ctx)
    for note in ctx.notes:  # e.g. no pose models under --shared: said now, not only at the end of the report
        print(f"sid bench: note: {note} (--shared {args.shared}; ${SHARED_ENV} sets the default)", file=sys.stderr)
    if args.list:
        for item in items:
            print(f"{item.name:<28} {item.what}")
        return 0
    try:
        chosen = select(items, args.only)
        check_output_folder(args.out)  # before the run, not after it
    except ValueError as exc:
        print(f"sid bench: {exc}", file=sys.stderr)
        return 2
    repo = repository() or Path(__file__).resolve().parent  # no checkout: git finds no commit to record
    machine = machine_info(repo)  # before the run: the load average is the one the run started under
    result = run_suite(chosen, ctx, _progress)
    run_settings = {"quick": args.quick, "only": args.only, "plan_runs": ctx.plan_runs, "pose_threads": args.threads,
                    "pose_provider": args.provider} | asdict(settings)  # fmt: skip
    report = build_report(machine, run_settings, result.stages, ctx.notes, result.failures)
    comparison = format_comparison(old, report) if old is not None else None
    try:
        with staged_output(args.out, ()) as staged:
            json_path, md_path = (staged.final(p) for p in write_report(report, staged.path, comparison))
    except OSError as exc:
        return fail("sid bench", exc)
    print(markdown(report, comparison), end="")
    print(f"wrote {json_path} and {md_path}", file=sys.stderr)
    if result.failures:
        failed = plural(len(result.failures), "benchmark")
        print(f"sid bench: {failed} failed: {', '.join(result.failures)}", file=sys.stderr)
        return ExitCode.FAILURE
    return 0

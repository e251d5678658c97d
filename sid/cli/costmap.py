"""``sid costmap SCENARIO --out DIR``: build a scenario's layered costmap and export it for navigation stacks."""

from __future__ import annotations

import argparse
import sys

from costmap.export import export_costmap
from costmap.mapfile import MapFileError
from sid.scenario.build import build_costmap
from sid.scenario.loader import ScenarioError, load_scenario


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "costmap",
        help="build a scenario's costmap and write map_server YAML/PGM, .npz, .mcap and a picture",
        description=__doc__.replace("``", ""),
    )
    parser.add_argument("scenario", help="scenario file (.json or .yaml); see docs/scenario.md")
    parser.add_argument("--out", required=True, help="output folder (created if missing)")
    parser.add_argument(
        "--no-social", action="store_true", help="leave out the social layer (the 'without recognition' baseline)"
    )
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    try:
        scenario = load_scenario(args.scenario)
        layered = build_costmap(scenario, social=not args.no_social)
    except (ScenarioError, MapFileError) as exc:
        print(f"sid costmap: {exc}", file=sys.stderr)
        return 2
    kind = "without recognition" if args.no_social else "social"
    paths = export_costmap(layered, args.out, robot=scenario.robot, title=f"{scenario.name}: {kind}")
    counts = {name: int((grid > 0).sum()) for name, grid in layered.grids.items()}
    print(
        f"{scenario.name}: {layered.spec.width}x{layered.spec.height} cells at {layered.spec.resolution} m, "
        f"{len(layered.inputs.people)} people, {len(layered.inputs.groups)} groups ({kind})"
    )
    print("non-zero cells per layer: " + ", ".join(f"{k} {v}" for k, v in counts.items()))
    for path in paths.values():
        print(f"wrote {path}")
    return 0

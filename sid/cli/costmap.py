"""``sid costmap SCENARIO [--out DIR]``: build a scenario's layered costmap and export it for navigation stacks."""

from __future__ import annotations

import argparse

from costmap.export import export_costmap
from costmap.layers.social import GROUPS, PEOPLE
from costmap.mapfile import MapFileError
from sid.cli.common import OutputFolderError, check_output_folder, fail, plain_text, print_written, staged_output
from sid.cli.planning import add_scenario_arguments
from sid.documents import plural
from sid.scenario.build import build_costmap
from sid.scenario.loader import ScenarioError, load_scenario
from sid.scenario.obstacles import outline

__all__ = ["add_parser", "run"]


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "costmap",
        help="build a scenario's costmap and write map_server YAML/PGM, .npz, .mcap and a picture",
        description=plain_text(__doc__),
    )
    add_scenario_arguments(
        parser,
        "costmap",
        "costmap.yaml + .pgm, .npz, .mcap and .png",
        "leave out the social layer (the 'without recognition' baseline)",
    )
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    try:
        check_output_folder(args.out)
        scenario = load_scenario(args.scenario)
        layered = build_costmap(scenario, social=not args.no_social)
    except (OutputFolderError, ScenarioError, MapFileError) as exc:
        return fail("sid costmap", exc)
    kind = "without recognition" if args.no_social else "social"
    outlines = [outline(ob) for ob in scenario.obstacles]
    try:
        with staged_output(args.out, ()) as staged:
            title = f"{scenario.name}: {kind}"
            written = export_costmap(layered, staged.path, robot=scenario.robot, title=title, outlines=outlines)
    except (OSError, ValueError) as exc:
        return fail("sid costmap", exc)
    paths = {key: staged.final(path) for key, path in written.items()}
    counts = {name: int((grid > 0).sum()) for name, grid in layered.grids.items()}
    people, groups = layered.inputs.get(PEOPLE), layered.inputs.get(GROUPS)
    print(
        f"{scenario.name}: {layered.spec.width}x{layered.spec.height} cells at {layered.spec.resolution} m, "
        f"{plural(len(people), 'person', 'people')}, {plural(len(groups), 'group')} ({kind})"
    )
    print("non-zero cells per layer: " + ", ".join(f"{k} {v}" for k, v in counts.items()))
    print_written(paths.values())
    return 0

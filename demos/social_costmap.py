"""Social costmap: the example conversation with and without recognition, side by side.

Loads examples/conversation.json (a robot, a goal behind three people in conversation, walls), builds the
LiDAR + inflation costmap a robot without recognition would have, and the same with the social layer (groups
found by sid.perception.groups.detect_groups), prints what cutting through the conversation would cost in each, and
writes one picture of both into a temporary folder.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import cv2
import numpy as np

from costmap.layers.social import GROUPS, PEOPLE, group_zone_polygon
from costmap.render import render_costmap
from sid.scenario.build import build_costmap
from sid.scenario.loader import load_scenario

SCENARIO = Path(__file__).resolve().parents[1] / "examples" / "conversation.json"


def main() -> None:
    scenario = load_scenario(SCENARIO)
    baseline = build_costmap(scenario, social=False)
    social = build_costmap(scenario)  # groups detected from the people's positions and facing

    print(f"{scenario.name}: {scenario.grid.width}x{scenario.grid.height} cells, {len(scenario.people)} people")
    people, groups = social.inputs[PEOPLE], social.inputs[GROUPS]
    for group in groups:
        zone = group_zone_polygon(group, people, scenario.layers.social.group_margin)
        print(f"group {group.members}: interaction zone {zone.area:.2f} m^2 around {np.round(group.interest_point, 2)}")

    # What a planner would pay to cut through the conversation: the o-space centre and the gaps between members.
    by_id = {p.id: p for p in people}
    for group in groups:
        members = [by_id[m] for m in group.members]
        gaps = [((a.x + b.x) / 2, (a.y + b.y) / 2) for i, a in enumerate(members) for b in members[i + 1 :]]
        probes = np.array([group.interest_point, *gaps])
        for name, layered in (("without recognition", baseline), ("with the social layer", social)):
            costs = layered.master.cost_at(probes)
            print(f"{name:>22}: o-space centre cost {costs[0]:3d}, gaps between members {costs[1:].tolist()}")

    picture = np.hstack(
        [
            render_costmap(baseline, robot=scenario.robot, title="without recognition (LiDAR + inflation)"),
            render_costmap(social, robot=scenario.robot, title="with the social layer"),
        ]
    )
    out = Path(tempfile.mkdtemp(prefix="sid_social_costmap_")) / "social_costmap.png"
    cv2.imwrite(str(out), picture)
    print(f"picture: {out}")


if __name__ == "__main__":
    main()

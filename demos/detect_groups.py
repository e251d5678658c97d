"""Detect conversational groups among a few people standing in front of the robot.

World frame (REP-103): x forward from the robot, y to its left, metres; theta is where each person faces (radians,
counter-clockwise from x). Run: python demos/detect_groups.py
"""

import math

from sid.perception.groups import GroupParams, detect_groups
from sid.perception.orientation import estimate_orientation
from sid.perception.people import Person
from sid.perception.skeleton import skeleton_world


def facing(x: float, y: float, tx: float, ty: float) -> float:
    """Yaw of someone at (x, y) looking at (tx, ty)."""
    return math.atan2(ty - y, tx - x)


people = [
    # Two people talking, 0.8 m apart, face to face.
    Person(1, 2.0, 1.2, facing(2.0, 1.2, 2.8, 1.2)),
    Person(2, 2.8, 1.2, facing(2.8, 1.2, 2.0, 1.2)),
    # Three in a triangle around (3.0, -1.0), each looking at its centre (a little off, as estimates are).
    Person(3, 3.0, -0.3, facing(3.0, -0.3, 3.0, -1.0) + 0.08),
    Person(4, 2.4, -1.35, facing(2.4, -1.35, 3.0, -1.0) - 0.05),
    Person(5, 3.6, -1.35, facing(3.6, -1.35, 3.0, -1.0)),
    # Someone walking away from the pair along the corridor, their back to it.
    Person(6, 1.5, 0.2, -math.pi / 2),
    # Someone whose facing the camera could not tell (theta None): never a member.
    Person(7, 4.2, 0.4, None),
]

# Facing directions normally come from 3D keypoints: PCA of a synthetic skeleton gives person 2's yaw back.
yaw, quality = estimate_orientation(skeleton_world(2.8, 1.2, facing(2.8, 1.2, 2.0, 1.2)))
told = "unknown (degenerate keypoints)" if yaw is None else f"{math.degrees(yaw):.1f} deg"
print(f"PCA facing of a synthetic skeleton: {told} (true 180.0), quality {quality:.2f}")

params = GroupParams()
print(f"Group parameters: {params}")
for group in detect_groups(people, params):
    x, y = group.interest_point
    print(
        f"group {list(group.members)}: interest point ({x:.2f}, {y:.2f}) m, "
        f"zone area {group.area:.4f} m^2, spread D {group.spread:.2f} m, zone vertices {len(group.zone)}"
    )

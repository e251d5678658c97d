"""sid records -> the fields of the ROS messages ``sid ros`` publishes, without importing ROS.

- ``grid_fields``: a costmap as a ``nav_msgs/OccupancyGrid`` KeepoutFilter mask (values from
  ``costmap.export.keepout_mask``; row 0 = lowest y, row-major, as the message wants);
- ``scene_markers``: people (body cylinder, facing arrow, id text) and groups (zone outline, id text) as
  ``visualization_msgs/Marker`` fields for RViz;
- ``groups_document``: the JSON of the groups topic (documented in docs/ros2.md).

Everything is in the costmap's global frame (REP-103: metres, radians, yaw counter-clockwise from +x).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from shapely.geometry import Polygon

from costmap.export import keepout_mask
from costmap.grid import Costmap2D
from costmap.layers.social import SocialParams, group_zone_polygon
from sid.perception.group import group_json
from sid.tracking.records import TrackedGroup, TrackedPerson

__all__ = [
    "BODY_HEIGHT",
    "BODY_RADIUS",
    "GROUP_COLOR",
    "GridFields",
    "MarkerFields",
    "PERSON_COLORS",
    "grid_fields",
    "groups_document",
    "quaternion_from_yaw",
    "scene_markers",
    "yaw_from_quaternion",
]

BODY_RADIUS = 0.2
"""Radius (m) of the cylinder drawn for a person."""
BODY_HEIGHT = 1.7
"""Height (m) of the cylinder drawn for a person."""
GROUP_COLOR = (0.9, 0.3, 0.1, 0.9)
PERSON_COLORS = {"standing": (0.1, 0.5, 0.9, 0.8), "walking": (0.1, 0.8, 0.4, 0.8)}


def quaternion_from_yaw(yaw: float) -> tuple[float, float, float, float]:
    """A rotation of ``yaw`` rad about +z as (x, y, z, w)."""
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


def yaw_from_quaternion(x: float, y: float, z: float, w: float) -> float:
    """The yaw (rad, in (-pi, pi]) of a rotation given as a quaternion (the z-axis heading; roll and pitch ignored)."""
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


@dataclass(frozen=True)
class GridFields:
    """The fields of a ``nav_msgs/OccupancyGrid``: header frame, ``info`` (resolution m/cell, width and height in
    cells, origin = the lower-left corner's pose) and ``data`` (int8, row-major, row 0 = lowest y)."""

    frame_id: str
    resolution: float
    width: int
    height: int
    origin_x: float
    origin_y: float
    origin_orientation: tuple[float, float, float, float]
    data: np.ndarray


def grid_fields(costmap: Costmap2D, frame_id: str) -> GridFields:
    """A costmap as the KeepoutFilter mask message (``costmap.export.keepout_mask``) in ``frame_id``."""
    mask = keepout_mask(costmap, frame_id)
    spec = mask.spec
    return GridFields(
        frame_id,
        spec.resolution,
        spec.width,
        spec.height,
        spec.origin_x,
        spec.origin_y,
        quaternion_from_yaw(mask.origin_yaw),
        mask.data.ravel(),
    )


@dataclass(frozen=True)
class MarkerFields:
    """The fields of one ``visualization_msgs/Marker`` (action ADD) that vary: ``kind`` names the Marker type
    (cylinder, arrow, line_strip, text_view_facing); pose (x, y, z, yaw); scale (m); RGBA colour in 0..1; points
    (line strips, z = 0.05 m); text."""

    namespace: str
    id: int
    kind: str
    x: float
    y: float
    z: float
    yaw: float
    scale: tuple[float, float, float]
    color: tuple[float, float, float, float]
    points: tuple[tuple[float, float], ...] = ()
    text: str = ""


def scene_markers(
    people: list[TrackedPerson], groups: list[TrackedGroup], margin: float = SocialParams.group_margin
) -> list[MarkerFields]:
    """Markers for RViz: per person a body cylinder, a facing arrow (when the facing is known) and its id; per
    conversation the outline of its interaction zone as the costmap paints it (``group_zone_polygon`` with the social
    layer's ``group_margin``, m) and its id. The node clears old markers first (DELETEALL), so ids are the tracks'."""
    markers = []
    for p in people:
        color = PERSON_COLORS[p.state]
        height = BODY_HEIGHT
        markers.append(
            MarkerFields(
                "people", p.id, "cylinder", p.x, p.y, height / 2, 0.0, (2 * BODY_RADIUS,) * 2 + (height,), color
            )
        )
        if p.theta is not None:
            markers.append(MarkerFields("facing", p.id, "arrow", p.x, p.y, 1.0, p.theta, (0.6, 0.06, 0.06), color))
        markers.append(
            MarkerFields(
                "people_ids", p.id, "text_view_facing", p.x, p.y, height + 0.2, 0.0, (0, 0, 0.25), color, (), f"{p.id}"
            )
        )
    by_id = {p.id: p.as_person() for p in people}
    for g in groups:
        # The detector's o-space polygon is a point for a face-to-face pair (no outline was drawn) and a few
        # millimetres across for a trio; the zone the mask paints is its hull with the members, grown by the margin.
        zone = group_zone_polygon(g.as_group(), by_id, margin) if g.kind == "conversation" else None
        if isinstance(zone, Polygon):  # margin 0 and members on a line: a line of no area, no outline
            outline = tuple((float(x), float(y)) for x, y in zone.exterior.coords)
            markers.append(
                MarkerFields("group_zones", g.id, "line_strip", 0.0, 0.0, 0.0, 0.0, (0.05, 0, 0), GROUP_COLOR, outline)
            )
        x, y = g.interest_point
        text = f"group {g.id}: {', '.join(str(m) for m in g.members)}"
        markers.append(
            MarkerFields("group_ids", g.id, "text_view_facing", x, y, 0.5, 0.0, (0, 0, 0.25), GROUP_COLOR, (), text)
        )
    return markers


def groups_document(
    stamp: float, frame_id: str, people: list[TrackedPerson], groups: list[TrackedGroup]
) -> dict[str, object]:
    """The groups topic's JSON: ``{"stamp": s, "frame_id", "people": [{"id", "x", "y", "theta", "vx", "vy",
    "state"}], "groups": [{"id", "kind", "members", "interest_point", "area", "spread", "zone"}]}`` (a group's
    fields as ``sid groups`` writes them, members being track ids)."""
    return {
        "stamp": stamp,
        "frame_id": frame_id,
        "people": [
            {
                "id": p.id,
                "x": round(p.x, 4),
                "y": round(p.y, 4),
                "theta": None if p.theta is None else round(p.theta, 4),
                "vx": round(p.vx, 4),
                "vy": round(p.vy, 4),
                "state": p.state,
            }
            for p in people
        ],
        "groups": [{"id": g.id, "kind": g.kind} | group_json(g.as_group()) for g in groups],
    }

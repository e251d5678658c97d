"""The paper's test layouts S1-S5 as parameterised scenes (world frame, metres, radians).

Every layout puts its people on a circle of ``radius`` around a formation centre ``centre_distance`` metres in
front of the camera (world (centre_distance, lateral)), at polar angles phi measured CCW from +x about that centre
(phi = 180 deg is the side nearest the camera), each person facing the centre (theta = phi + 180 deg):

====  ==================================================  ========================  ======  ======
name  paper                                               phi (deg)                 radius  centre
====  ==================================================  ========================  ======  ======
S1    two people 0.8 m apart facing each other            90, -90 (side by side)    0.40 m  2.2 m
S2    three in a semicircle facing the camera             -60, 0, 60 (far half)     0.75 m  1.9 m
S3    three on an equilateral triangle facing its centre  0, 120, 240               0.69 m  2.2 m
S4    four in a semicircle (facing the camera)            -67.5, -22.5, 22.5, 67.5  0.80 m  1.9 m
S5    four in a circle                                    45, 135, 225, 315         0.80 m  2.3 m
====  ==================================================  ========================  ======  ======

"Facing the camera" (S2, S4) is read as: the semicircle lies on the far side of its centre and opens towards the
camera, so every member faces the centre and turns its front to the camera. The S3 triangle has 1.2 m sides
(radius 1.2 / sqrt(3)). S5 stands as a square with one side towards the camera, the orientation where members
hide each other least (at 0 deg the far member stands straight behind the near one); even so a few keypoints of
the far members are hidden behind the near ones. With these defaults everyone stands 1.5-3.0 m in front of a
camera mounted 0.9 m high, as in the paper, and everyone forms one conversational group.

``focus_offset`` makes everyone face a point that much nearer to the camera than the centre (a group that opens
towards the camera); ``rotation`` turns the whole formation about its centre; ``jitter_xy`` / ``jitter_theta``
add Gaussian noise (seeded by ``seed``) to positions and facing directions, as real people never stand on an exact
circle; ``height`` sets everyone's height, ``height_jitter`` its spread. ``VARIATIONS`` lists the documented variations
that ``variations(name)`` applies.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from sid.checks import check_numbers
from sid.errors import InputError
from sid.perception.mount import CameraMount
from sid.synthetic.scene import Scene, ScenePerson

__all__ = ["Formation", "LAYOUTS", "LayoutSpec", "VARIATIONS", "layout", "variations"]


@dataclass(frozen=True)
class LayoutSpec:
    """The shape of one layout: polar angles of its members (deg), default radius and centre distance (m), and the
    turn (deg) its rotated variations use."""

    description: str
    angles_deg: tuple[float, ...]
    radius: float
    centre_distance: float
    turn_deg: float = 15.0


LAYOUTS: dict[str, LayoutSpec] = {
    "S1": LayoutSpec("two people 0.8 m apart facing each other", (90.0, -90.0), 0.40, 2.2),
    "S2": LayoutSpec("three in a semicircle facing the camera", (-60.0, 0.0, 60.0), 0.75, 1.9),
    "S3": LayoutSpec("three on an equilateral triangle facing its centre", (0.0, 120.0, 240.0), 1.2 / np.sqrt(3), 2.2),
    "S4": LayoutSpec("four in a semicircle facing the camera", (-67.5, -22.5, 22.5, 67.5), 0.80, 1.9),
    "S5": LayoutSpec("four in a circle", (45.0, 135.0, 225.0, 315.0), 0.80, 2.3, turn_deg=5.0),
}


@dataclass(frozen=True)
class Formation:
    """How a layout is placed: formation centre (m), radius (m, None = the layout's), rotation (rad, CCW seen
    from above), Gaussian jitter of positions (m) and facing directions (rad), heights (m), random seed.

    focus_offset (m): everyone faces a point this much nearer to the camera than the centre instead of the centre
    itself, so the group opens towards the camera (the paper authors' own two-person recording shows such a V,
    docs/parameters.md). 0: face the centre.
    """

    centre_distance: float | None = None
    lateral: float = 0.0
    radius: float | None = None
    rotation: float = 0.0
    jitter_xy: float = 0.0
    jitter_theta: float = 0.0
    focus_offset: float = 0.0
    height: float = 1.70
    height_jitter: float = 0.0
    seed: int = 0

    def __post_init__(self) -> None:
        check_numbers("layout", self, ("lateral", "rotation", "focus_offset", "height"))
        check_numbers("layout", self, ("jitter_xy", "jitter_theta", "height_jitter"), low=0)
        given = [name for name in ("centre_distance", "radius") if getattr(self, name) is not None]  # None: layout's
        check_numbers("layout", self, given, low=0, low_open=True, unit="metres")


# The documented variations of every layout: as described; turned by -turn and +turn about its centre (15 deg;
# 5 deg for S5, where a larger turn hides a member almost completely behind another); 0.15 m nearer and 0.15 m
# further; two samples of natural irregularity (5 cm position, 5 deg facing jitter).
VARIATIONS: tuple[dict[str, Any], ...] = (
    {},
    {"turn": -1.0},
    {"turn": 1.0},
    {"distance_offset": -0.15},
    {"distance_offset": 0.15},
    {"jitter_xy": 0.05, "jitter_theta": np.radians(5.0), "seed": 1},
    {"jitter_xy": 0.05, "jitter_theta": np.radians(5.0), "seed": 2},
)


def layout(
    name: str,
    formation: Formation | None = None,
    mount: CameraMount | None = None,
    wall_distance: float | None = 5.0,
    **options: Any,
) -> Scene:
    """Scene of layout ``name`` (S1-S5, case-insensitive) placed by ``formation`` (or by keyword ``options``,
    the fields of ``Formation``). Person ids are 0..n-1 in the order of the layout's angles; one group of all."""
    spec = _spec(name)
    formation = replace(formation or Formation(), **options)
    radius = spec.radius if formation.radius is None else formation.radius
    centre_x = spec.centre_distance if formation.centre_distance is None else formation.centre_distance
    centre = np.array([centre_x, formation.lateral])
    rng = np.random.default_rng(formation.seed)
    n = len(spec.angles_deg)
    phi = np.radians(np.asarray(spec.angles_deg)) + formation.rotation
    xy = centre + radius * np.stack([np.cos(phi), np.sin(phi)], axis=1) + rng.normal(0.0, formation.jitter_xy, (n, 2))
    focus = centre - np.array([formation.focus_offset, 0.0])
    towards = focus - xy
    if np.any(np.hypot(towards[:, 0], towards[:, 1]) < 1e-6):
        raise InputError(
            f"layout {name}: a person stands on the point everyone faces (focus_offset {formation.focus_offset})"
        )
    theta = np.arctan2(towards[:, 1], towards[:, 0]) + rng.normal(0.0, formation.jitter_theta, n)
    theta = np.angle(np.exp(1j * theta))
    heights = formation.height + rng.normal(0.0, formation.height_jitter, n)
    people = tuple(
        ScenePerson(i, float(xy[i, 0]), float(xy[i, 1]), float(theta[i]), float(heights[i])) for i in range(n)
    )
    return Scene(name.upper(), people, (tuple(range(n)),), mount or CameraMount(), wall_distance)


def variations(name: str, **options: Any) -> list[Scene]:
    """The scenes of layout ``name`` under each entry of ``VARIATIONS``, each applied to the formation the caller's
    ``options`` (``layout``'s keywords) describe.

    ``distance_offset`` moves the formation centre from the caller's centre distance (default the layout's; m);
    ``turn`` adds that multiple of the layout's ``turn_deg`` to the caller's rotation; a variation's ``seed`` is
    added to the caller's. ``jitter_xy`` and ``jitter_theta`` are the jitter variations' own and are refused here
    (ValueError): pass them to ``layout``.
    """
    spec = _spec(name)
    own = sorted({"jitter_xy", "jitter_theta"} & set(options))
    if own:
        raise InputError(
            f"variations of {name}: {', '.join(own)} are set by the jitter variations; use layout() instead"
        )
    options = dict(options)
    fields = Formation.__dataclass_fields__
    formation = replace(
        options.pop("formation", None) or Formation(), **{k: options.pop(k) for k in list(options) if k in fields}
    )
    centre = spec.centre_distance if formation.centre_distance is None else formation.centre_distance
    scenes = []
    for variation in VARIATIONS:
        variation = dict(variation)
        changes = {
            "centre_distance": centre + variation.pop("distance_offset", 0.0),
            "rotation": formation.rotation + np.radians(variation.pop("turn", 0.0) * spec.turn_deg),
            "seed": formation.seed + variation.pop("seed", 0),
        }
        scenes.append(layout(name, replace(formation, **changes, **variation), **options))
    return scenes


def _spec(name: str) -> LayoutSpec:
    spec = LAYOUTS.get(str(name).upper())
    if spec is None:
        raise InputError(f"unknown layout {name!r}; known layouts: {', '.join(LAYOUTS)}")
    return spec

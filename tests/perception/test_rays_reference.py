"""The ray crossings' two paths (``ray_meetings`` on numpy arrays, ``member_crossings`` on Python numbers) held to a
plain reference: shapely's intersection of the two 1.5 m facing segments, and the face-to-face midpoint rule."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from shapely.geometry import LineString, Point

from sid.perception.groups import GroupParams
from sid.perception.rays import ray_meetings
from sid.perception.zone import member_crossings

RAYS = GroupParams(method="rays")


def reference_meeting(pi: complex, fi: complex, pj: complex, fj: complex, params: GroupParams) -> complex | None:
    """Where the rays of two people meet (world frame, m), or None: the crossing of their facing segments (length
    ``ray_length``); for a pair facing each other (each within ``facing_tolerance`` of the other, at most two ray
    lengths apart) the midpoint, when their segments do not cross or cross nearly anti-parallel (within 20 degrees)."""
    length = params.ray_length
    d = pj - pi
    distance = abs(d)
    cos_tolerance = math.cos(params.facing_tolerance)
    face_to_face = (
        0 < distance <= 2 * length
        and (d.real * fi.real + d.imag * fi.imag) >= cos_tolerance * distance
        and -(d.real * fj.real + d.imag * fj.imag) >= cos_tolerance * distance
    )
    sine = fi.real * fj.imag - fi.imag * fj.real
    a = LineString([(pi.real, pi.imag), ((pi + length * fi).real, (pi + length * fi).imag)])
    b = LineString([(pj.real, pj.imag), ((pj + length * fj).real, (pj + length * fj).imag)])
    crossing = abs(sine) > 1e-9 and a.intersects(b)
    if crossing and not (face_to_face and abs(sine) < math.sin(math.radians(20))):
        point = a.intersection(b)
        assert isinstance(point, Point)
        return complex(point.x, point.y)
    return 0.5 * (pi + pj) if face_to_face else None


def random_scene(rng: np.random.Generator, n: int) -> tuple[list[complex], list[complex]]:
    """People 0-3 m apart; half face someone else (with 0-40 degrees of error), half anywhere."""
    positions = [complex(*rng.uniform(0, 3, 2)) for _ in range(n)]
    facing = []
    for k, p in enumerate(positions):
        if rng.random() < 0.5:
            other = positions[(k + 1 + int(rng.integers(n - 1))) % n]
            angle = math.atan2((other - p).imag, (other - p).real) + rng.normal(0, math.radians(20))
        else:
            angle = rng.uniform(-math.pi, math.pi)
        facing.append(complex(math.cos(angle), math.sin(angle)))
    return positions, facing


@pytest.mark.parametrize("seed", range(25))
def test_both_paths_meet_where_the_segments_cross_or_at_the_face_to_face_midpoint(seed: int) -> None:
    rng = np.random.default_rng(seed)
    positions, facing = random_scene(rng, int(rng.integers(2, 10)))
    pairs = list(itertools.combinations(range(len(positions)), 2))
    expected = {
        (i, j): point
        for i, j in pairs
        if (point := reference_meeting(positions[i], facing[i], positions[j], facing[j], RAYS)) is not None
    }
    meetings = ray_meetings(np.array(positions), np.array(facing), RAYS)
    found = dict(
        zip(zip(meetings.first.tolist(), meetings.second.tolist(), strict=True), meetings.points.tolist(), strict=True)
    )
    assert found.keys() == expected.keys()
    for key, point in expected.items():
        assert abs(found[key] - point) < 1e-9, key
    (small,) = member_crossings(positions, facing, [list(range(len(positions)))], RAYS)
    assert small == [found[key] for key in pairs if key in found]


def test_the_reference_rules_on_hand_made_pairs() -> None:
    # Crossing rays: two people 1 m apart facing 45 degrees inwards meet 0.5 m ahead of the middle.
    inwards = complex(math.cos(math.pi / 4), math.sin(math.pi / 4))
    assert reference_meeting(0j, inwards, 1 + 0j, complex(-inwards.real, inwards.imag), RAYS) == pytest.approx(
        0.5 + 0.5j
    )
    # Face to face, 1 m apart, looking straight at each other: the midpoint.
    assert reference_meeting(0j, 1 + 0j, 1 + 0j, -1 + 0j, RAYS) == pytest.approx(0.5 + 0j)
    # Back to back: nothing.
    assert reference_meeting(0j, -1 + 0j, 1 + 0j, 1 + 0j, RAYS) is None

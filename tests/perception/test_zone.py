"""Where members' rays meet and the zone they make (``sid.perception.zone``): the hull and shoelace against shapely,
the crossings on Python numbers against the ray method's numpy ones (``sid.perception.rays.ray_meetings``)."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from sid.perception.groups import GroupParams
from sid.perception.rays import ray_meetings
from sid.perception.zone import convex_hull, member_crossings, shoelace, spread

RAYS = GroupParams(method="rays")

MILLIMETRES = st.integers(-5000, 5000).map(lambda v: v / 1000)


@settings(max_examples=300, deadline=None)
@given(st.lists(st.tuples(MILLIMETRES, MILLIMETRES), min_size=3, max_size=30))
def test_hull_area_and_centroid_match_shapely(coords):
    points = [complex(x, y) for x, y in coords]
    hull = convex_hull(points)
    reference = shapely.convex_hull(shapely.multipoints(np.array(coords)))
    if reference.geom_type != "Polygon" or reference.area < 1e-6:
        return  # degenerate sets are handled apart (area 0, mean of crossings)
    area, centre = shoelace(hull)
    assert area == pytest.approx(reference.area, rel=1e-9, abs=1e-9)
    assert (centre.real, centre.imag) == pytest.approx(reference.centroid.coords[0], abs=1e-6)


@pytest.mark.parametrize("seed", range(30))
def test_the_ospace_zone_arithmetic_on_python_numbers_matches_the_numpy_one(seed):
    # Groups of 2-8 members, random or on a grid with ties (face to face, parallel, crossing at a ray's end), some
    # facings unknown: the same crossings, in the same order, to the last bit.
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 20))
    if seed % 2:
        positions = (rng.uniform(0, 3, n) + 1j * rng.uniform(0, 3, n)).tolist()
        angles = rng.uniform(-math.pi, math.pi, n)
    else:
        cells = rng.choice(16, n, replace=n > 16)
        positions = [complex(0.75 * (c % 4), 0.75 * (c // 4)) for c in cells]
        angles = rng.integers(0, 8, n) * math.pi / 4
    facing = [complex(math.cos(a), math.sin(a)) if rng.random() > 0.15 else complex(math.nan, math.nan) for a in angles]
    order = rng.permutation(n).tolist()
    order_before = list(order)
    groups = []
    while order:
        size = int(rng.integers(2, 9))
        groups.append(sorted(order[:size]))
        order = order[size:]
    crossings = member_crossings(positions, facing, groups, RAYS)
    for group, found in zip(groups, crossings, strict=True):
        pairs = tuple(np.array(side, dtype=int) for side in zip(*itertools.combinations(group, 2), strict=True))
        if not pairs:  # a single member
            assert found == []
            continue
        meetings = ray_meetings(np.array(positions), np.array(facing), RAYS, pairs)
        assert found == meetings.points.tolist()
    # D does not depend on the members' order (exact sums).
    centre = complex(*rng.uniform(0, 3, 2))
    assert spread([positions[i] for i in order_before], centre) == spread(
        [positions[i] for i in reversed(order_before)], centre
    )

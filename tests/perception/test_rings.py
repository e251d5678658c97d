"""Wide rings: the circle fit against numpy's least squares, and the joining of arcs into one group."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sid.perception.groups import GroupParams, detect_groups
from sid.perception.people import Person
from sid.perception.rings import RingModel, fit_ring

DEFAULTS = GroupParams()
NO_RINGS = GroupParams(ring_radius_max=0.0)


def ring_of(n: int, radius: float, seed: int | None = None, centre: complex = 0j) -> list[Person]:
    """n people evenly on a circle (m) facing its centre; with a seed, 5 cm and 3 degrees of position jitter and
    10 degrees of facing noise."""
    rng = np.random.default_rng(seed)
    jitter = (0.05, math.radians(3), math.radians(10)) if seed is not None else (0.0, 0.0, 0.0)
    people = []
    for i in range(n):
        a = 2 * math.pi * i / n + rng.normal(0, jitter[1])
        x = centre.real + radius * math.cos(a) + rng.normal(0, jitter[0])
        y = centre.imag + radius * math.sin(a) + rng.normal(0, jitter[0])
        people.append(Person(i, x, y, a + math.pi + rng.normal(0, jitter[2]), 1.0))
    return people


def sizes(people: list[Person], params: GroupParams = DEFAULTS) -> list[int]:
    return sorted((len(g.members) for g in detect_groups(people, params)), reverse=True)


@pytest.mark.parametrize("seed", range(10))
def test_the_closed_form_fit_is_numpys_least_squares(seed: int) -> None:
    rng = np.random.default_rng(seed)
    points = (rng.normal(3, 2, 8) + 1j * rng.normal(-1, 2, 8)).tolist()
    ring = fit_ring(points)
    assert ring is not None
    xy = np.array([(p.real, p.imag) for p in points])
    design = np.column_stack((2 * xy, np.ones(len(xy))))
    (a, b, c), *_ = np.linalg.lstsq(design, (xy**2).sum(axis=1), rcond=None)
    assert ring.centre == pytest.approx(complex(a, b), abs=1e-9)
    assert ring.radius == pytest.approx(math.sqrt(c + a * a + b * b), abs=1e-9)
    assert ring.deviation == pytest.approx(np.abs(np.hypot(xy[:, 0] - a, xy[:, 1] - b) - ring.radius).max(), abs=1e-9)


def test_no_circle_through_fewer_than_three_points_or_a_line() -> None:
    assert fit_ring([0j, 1 + 0j]) is None
    assert fit_ring([0j, 1 + 1j, 2 + 2j, 3 + 3j]) is None
    assert fit_ring([1 + 0j, 1j, -1 + 0j]).radius == pytest.approx(1.0)


@pytest.mark.parametrize(("n", "radius"), [(8, 1.1), (10, 1.35), (12, 1.6)])
def test_wide_circles_come_out_whole_where_the_search_alone_cuts_them(n: int, radius: float) -> None:
    assert sizes(ring_of(n, radius)) == [n]
    assert sizes(ring_of(n, radius), NO_RINGS) != [n]  # the search's radii end at 0.8 m: arcs
    whole = sum(sizes(ring_of(n, radius, seed)) == [n] for seed in range(10))
    assert whole == 10


@pytest.mark.parametrize(("n", "radius"), [(7, 1.6), (7, 1.75), (9, 1.6)])
def test_a_circle_the_search_cuts_into_arcs_of_fewer_than_six_each_comes_out_whole(n: int, radius: float) -> None:
    """Seven on 1.6 m came out of the search as arcs of 2, 2 and 3: joins of two parts at a time need six people
    between them, so none was made, though all seven make one ring."""
    assert sizes(ring_of(n, radius), NO_RINGS) != [n]
    assert sizes(ring_of(n, radius)) == [n]
    assert sum(sizes(ring_of(n, radius, seed)) == [n] for seed in range(10)) == 10


@pytest.mark.parametrize(("n", "radius", "unknown"), [(12, 1.6, 3), (10, 1.35, 0)])
def test_someone_of_unknown_facing_on_the_circle_joins_the_ring(n: int, radius: float, unknown: int) -> None:
    """A half-hidden member (facing unknown) standing on the circle, in the gap between two members, was left
    out: only people with a facing could join a ring."""
    people = ring_of(n, radius)
    people[unknown] = Person(unknown, people[unknown].x, people[unknown].y)
    assert sizes(people) == [n]
    outside = [*ring_of(n, radius)[:-1], Person(n - 1, radius + 0.8, 0.0)]  # off the circle: not a member
    assert sizes(outside)[0] == n - 1


def test_people_of_unknown_facing_never_make_a_ring() -> None:
    """Five on a 1.6 m circle facing its centre are arcs; a sixth of unknown facing does not complete a ring."""
    people = ring_of(6, 1.6)
    people[5] = Person(5, people[5].x, people[5].y)
    assert n_largest(people) < 6


def n_largest(people: list[Person]) -> int:
    return max(sizes(people), default=0)


def test_two_neighbouring_conversations_are_not_joined() -> None:
    # Two circles of four, 1.2 m from each other's nearest member, each facing its own centre.
    people = ring_of(4, 0.6) + [replace_id(p, 10 + p.id, dx=2.4) for p in ring_of(4, 0.6)]
    assert sizes(people) == [4, 4]
    # Three circles of three on a wide triangle: their people stand on no one circle.
    triples = [
        replace_id(p, 10 * k + p.id, dx=2.0 * math.cos(2.1 * k), dy=2.0 * math.sin(2.1 * k))
        for k in range(3)
        for p in ring_of(3, 0.45)
    ]
    assert sizes(triples) == [3, 3, 3]


def test_someone_inside_the_ring_keeps_its_arcs_apart() -> None:
    people = ring_of(10, 1.35)
    assert sizes(people) == [10]
    intruder = Person(99, 0.5, 0.0, 0.0, 1.0)  # inside the o-space, facing away from the centre
    assert sizes([*people, intruder]) != [10]


def test_the_ring_is_the_same_whatever_the_order_position_and_heading() -> None:
    people = ring_of(12, 1.6, seed=3)
    expected = {tuple(sorted(g.members)) for g in detect_groups(people)}
    angle, dx, dy = 2.2, 812.5, -377.25
    c, s = math.cos(angle), math.sin(angle)
    moved = [Person(p.id, c * p.x - s * p.y + dx, s * p.x + c * p.y + dy, p.theta + angle, 1.0) for p in people]
    assert {tuple(sorted(g.members)) for g in detect_groups(moved[::-1])} == expected


@pytest.mark.parametrize(("field", "value"), [("radius_max", -1.0), ("tolerance", math.inf), ("facing_tolerance", 2.0)])
def test_bad_ring_constants_are_refused_by_name(field: str, value: float) -> None:
    with pytest.raises(ValueError, match=f"rings: {field}"):
        RingModel(**({"radius_max": 2.0, "tolerance": 0.2, "facing_tolerance": 0.6} | {field: value}))
    with pytest.raises(ValueError, match=f"groups: ring_{field}"):
        GroupParams(**{f"ring_{field}": value})


def replace_id(p: Person, new_id: int, dx: float = 0.0, dy: float = 0.0) -> Person:
    return Person(new_id, p.x + dx, p.y + dy, p.theta, p.orientation_quality)

"""The o-space search's two fast paths (small scenes on Python numbers, crowds on numpy arrays) held to one plain
reference of what they compute: the cost of each person joining each candidate o-space, as the model's formulas
say it (``sid.perception.ospace``'s docstring), and the canonical group labels."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial import cKDTree

import sid.perception.ospace as ospace
from sid.perception.groups import GroupParams

MODEL = GroupParams().ospace_model


def reference_costs(people, candidates, model) -> dict[tuple[int, int], float]:
    """{(candidate k, person j): cost m^2} for every person who may join candidate k, written from the formulas.

    people: (x, y, facing yaw or None, facing weight, slack rad); candidates: (centre x, y, radius R).
    Known facing: e = (rho - R)^2 + a 2 R rho (1 - cos(max(0, phi - s))), phi the angle between the facing and the
    direction to the centre; unknown: u = (rho - R)^2 + unknown_cost^2; weight w: w e + (1 - w) u. A person joins
    when within reach of the centre, cheaper than alone, and nobody else within reach stands between them and the
    centre closer than body_radius to the line (strictly between, along it).
    """
    out = {}
    for k, (cx, cy, radius) in enumerate(candidates):
        for j, (x, y, yaw, weight, slack) in enumerate(people):
            rho = math.hypot(cx - x, cy - y)
            if rho >= model.reach:
                continue
            on_circle = (rho - radius) ** 2
            unknown = on_circle + model.unknown_cost**2
            if yaw is None:
                cost = unknown
            else:
                phi = abs(math.remainder(math.atan2(cy - y, cx - x) - yaw, math.tau)) if rho > 0 else 0.0
                known = on_circle + model.angular_weight * 2 * radius * rho * (1 - math.cos(max(0.0, phi - slack)))
                cost = weight * known + (1 - weight) * unknown
            if cost >= model.alone_price:
                continue
            if any(_between((x, y), (cx, cy), (bx, by), model) for b, (bx, by, *_) in enumerate(people) if b != j):
                continue
            out[k, j] = cost
    return out


def _between(a, centre, b, model) -> bool:
    """Whether b, within reach of the centre, stands between a and the centre within body_radius of the line."""
    if math.hypot(centre[0] - b[0], centre[1] - b[1]) >= model.reach:
        return False
    sx, sy = centre[0] - a[0], centre[1] - a[1]
    rx, ry = b[0] - a[0], b[1] - a[1]
    length2 = sx * sx + sy * sy
    along = (rx * sx + ry * sy) / length2
    distance = abs(rx * sy - ry * sx) / math.sqrt(length2)
    return 0 < along < 1 and distance < model.body_radius


def random_people(rng: np.random.Generator, n: int) -> list[tuple[float, float, float | None, float, float]]:
    people = []
    for _ in range(n):
        yaw = None if rng.random() < 0.15 else float(rng.uniform(-math.pi, math.pi))
        weight = 0.0 if yaw is None else float(rng.choice([1.0, rng.uniform(0.5, 1.0)]))
        people.append((float(rng.uniform(0, 4)), float(rng.uniform(0, 4)), yaw, weight, float(rng.uniform(0, 0.8))))
    return people


def random_candidates(rng: np.random.Generator, people, count: int) -> list[tuple[float, float, float]]:
    """Candidates near the people (each person's proposal at a random radius, moved a little) and anywhere."""
    out = []
    for _ in range(count):
        x, y, yaw, *_ = people[int(rng.integers(len(people)))]
        radius = float(rng.uniform(MODEL.radius_min, MODEL.radius_max))
        turn = 0.0 if yaw is None else yaw
        out.append(
            (x + radius * math.cos(turn) + rng.normal(0, 0.2), y + radius * math.sin(turn) + rng.normal(0, 0.2), radius)
        )
    return out


def _small_path(people, candidates, model) -> dict[tuple[int, int], float]:
    table = [
        (x, y, *((0.0, 0.0) if yaw is None else (math.cos(yaw), math.sin(yaw))), w, math.cos(s), math.sin(s))
        for x, y, yaw, w, s in people
    ]
    scene = ospace._SmallScene(table, [yaw is not None for _, _, yaw, *_ in people], model)
    rows = scene.rows([(complex(cx, cy), r) for cx, cy, r in candidates])
    return {(k, j): cost for k, (entries, _) in enumerate(rows) for j, cost in entries}


def _crowd_path(people, candidates, model) -> dict[tuple[int, int], float]:
    table = np.array(
        [
            (x, y, *((0.0, 0.0) if yaw is None else (math.cos(yaw), math.sin(yaw))), w, math.cos(s), math.sin(s))
            for x, y, yaw, w, s in people
        ]
    ).T
    centres = np.array([complex(cx, cy) for cx, cy, _ in candidates])
    radii = np.array([r for *_, r in candidates])
    near = ospace._near(cKDTree(table[:2].T), centres, model.reach)
    cost = ospace._costs(table[:, near], centres, radii, near >= 0, model)
    return {(k, int(near[k, a])): float(cost[k, a]) for k, a in zip(*np.nonzero(np.isfinite(cost)), strict=True)}


@pytest.mark.parametrize("seed", range(20))
def test_both_paths_price_every_candidate_as_the_formulas_do(seed: int) -> None:
    rng = np.random.default_rng(seed)
    people = random_people(rng, int(rng.integers(2, 25)))
    candidates = random_candidates(rng, people, 40)
    reference = reference_costs(people, candidates, MODEL)
    assert reference, "the scene should let someone join something"
    for name, path in (("small", _small_path), ("crowd", _crowd_path)):
        found = path(people, candidates, MODEL)
        assert found.keys() == reference.keys(), f"{name}: who may join which candidate differs"
        for key, cost in reference.items():
            assert found[key] == pytest.approx(cost, rel=1e-9, abs=1e-12), (name, key)


def test_the_reference_refuses_someone_behind_a_person_standing_in_the_way() -> None:
    people = [(0.0, 0.0, 0.0, 1.0, 0.4), (0.6, 0.0, math.pi, 1.0, 0.4), (1.2, 0.0, math.pi, 1.0, 0.4)]
    centre = [(0.9, 0.0, 0.3)]  # between the last two: the first has the middle one in the way
    reference = reference_costs(people, centre, MODEL)
    assert (0, 0) not in reference and {(0, 1), (0, 2)} <= reference.keys()
    assert _small_path(people, centre, MODEL).keys() == _crowd_path(people, centre, MODEL).keys() == reference.keys()


def reference_labels(choices: list[int], known: list[bool]) -> list[int]:
    """Group labels numbered by each group's lowest member, -1 alone; a candidate needs two members, one at least
    with a known facing."""
    members: dict[int, list[int]] = {}
    for j, c in enumerate(choices):
        if c >= 0:
            members.setdefault(c, []).append(j)
    kept = [c for c, js in members.items() if len(js) >= 2 and any(known[j] for j in js)]
    order = sorted(kept, key=lambda c: members[c][0])
    label = {c: i for i, c in enumerate(order)}
    return [label.get(c, -1) for c in choices]


@pytest.mark.parametrize("seed", range(30))
def test_canonical_labels_match_the_plain_rule(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 15))
    choices = [int(c) for c in rng.integers(-1, 6, n)]
    known = [bool(k) for k in rng.random(n) < 0.8]
    labels, behind = ospace._canonical(choices, known)
    assert labels == reference_labels(choices, known)
    assert [choices[labels.index(g)] for g in range(len(behind))] == behind

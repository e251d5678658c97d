"""The o-space assignment on its own: the fitted centre and radius, the crowd path against the small one, checks."""

from __future__ import annotations

import cmath
import dataclasses
import itertools
import math

import numpy as np
import pytest

import sid.perception.ospace as ospace
from sid.perception.groups import GroupParams
from sid.perception.ospace import OSpaceModel, find_ospaces

MODEL = GroupParams().ospace_model
PAIRS = GroupParams(coarse_pair_reach=1.5).coarse_ospace_model  # close pairs propose their o-space too


def inputs(people: list[tuple[float, float, float | None]]) -> tuple[list[complex], list[complex], list[float]]:
    positions = [complex(x, y) for x, y, _ in people]
    facing = [complex(math.cos(t), math.sin(t)) if t is not None else complex(np.nan, np.nan) for *_, t in people]
    return positions, facing, [1.0] * len(people)


def test_a_face_to_face_pair_gets_its_midpoint_and_half_its_distance():
    [group] = find_ospaces(*inputs([(1.0, 2.0, 0.0), (2.2, 2.0, math.pi)]), MODEL)
    assert group.members.tolist() == [0, 1]
    assert group.centre == pytest.approx(complex(1.6, 2.0)) and group.radius == pytest.approx(0.6)


def test_each_group_fits_its_own_radius():
    # Two circles of 4 facing their centres, radii 0.4 and 0.75 m, 5 m apart.
    people = []
    for centre, radius in ((0.0, 0.4), (5.0, 0.75)):
        for k in range(4):
            a = math.pi / 2 * k + 0.2
            people.append((centre + radius * math.cos(a), radius * math.sin(a), a + math.pi))
    groups = find_ospaces(*inputs(people), MODEL)
    assert [g.members.tolist() for g in groups] == [[0, 1, 2, 3], [4, 5, 6, 7]]
    assert [g.radius for g in groups] == pytest.approx([0.4, 0.75])
    assert [g.centre for g in groups] == pytest.approx([0j, 5 + 0j], abs=1e-9)


def test_the_crowd_path_gives_what_the_small_scene_path_gives(monkeypatch):
    rng = np.random.default_rng(3)
    people = []
    for k in range(9):  # circles of 3 centres 2.4 m apart, noisy
        cx, cy = 2.4 * (k % 3), 2.4 * (k // 3)
        for j in range(3):
            a = 2 * math.pi * j / 3 + rng.normal(0, 0.2)
            x, y = cx + 0.7 * math.cos(a) + rng.normal(0, 0.05), cy + 0.7 * math.sin(a) + rng.normal(0, 0.05)
            people.append((x, y, math.atan2(cy - y, cx - x) + rng.normal(0, 0.3)))
    crowd = find_ospaces(*inputs(people), MODEL)
    monkeypatch.setattr(ospace, "_SMALL_PEOPLE_MAX", 1000)
    small = find_ospaces(*inputs(people), MODEL)
    assert [g.members.tolist() for g in crowd] == [g.members.tolist() for g in small]
    assert [g.centre for g in crowd] == pytest.approx([g.centre for g in small])
    assert len(crowd) >= 7


@pytest.mark.parametrize("seed", range(12))
@pytest.mark.parametrize("slack", [0.0, 0.4, math.pi / 4])
@pytest.mark.parametrize("model", [MODEL, PAIRS], ids=["own proposals", "pair proposals"])
def test_the_two_paths_agree_on_random_scenes(seed: int, slack: float, model: OSpaceModel, monkeypatch) -> None:
    scene = random_scene(seed)
    slacks = [slack] * len(scene[0])
    monkeypatch.setattr(ospace, "_SMALL_PEOPLE_MAX", 0)
    crowd = find_ospaces(*scene, model, slacks)
    monkeypatch.setattr(ospace, "_SMALL_PEOPLE_MAX", 1000)
    small = find_ospaces(*scene, model, slacks)
    assert [g.members.tolist() for g in crowd] == [g.members.tolist() for g in small]
    assert [g.centre for g in crowd] == pytest.approx([g.centre for g in small], abs=1e-9)
    assert [g.radius for g in crowd] == pytest.approx([g.radius for g in small], abs=1e-9)


@pytest.mark.parametrize("small", [False, True])
def test_nobody_joins_across_someone_standing_in_the_way(small: bool, monkeypatch) -> None:
    # Three in a row facing along it: the middle one stands on the line from each end to any centre between them.
    monkeypatch.setattr(ospace, "_SMALL_PEOPLE_MAX", 1000 if small else 0)
    people = [(0.0, 0.0, 0.0), (0.6, 0.0, math.pi), (1.2, 0.0, math.pi)]
    assert [g.members.tolist() for g in find_ospaces(*inputs(people), MODEL)] == [[0, 1]]
    assert find_ospaces(*inputs([people[0], people[2]]), MODEL)[0].members.tolist() == [0, 1]


# The groups the detector gives (members per seed of ``random_scene``, no facing slack), recorded when the facing
# cone and the alone price came in and again when unknown facings began to count towards opening (both paths, small
# and crowd, give these): any change to the assignment shows here.
EXPECTED_MEMBERS = [
    [[0, 10], [1, 2, 20], [3, 11, 25], [4, 9, 15], [5, 21], [6, 22, 23], [7, 13], [12, 14, 19], [17, 24]],
    [[0, 2, 5, 12], [4, 6, 10, 14]],
    [[0, 5, 7, 11, 13, 23], [1, 21, 22], [3, 8, 20], [9, 14, 17]],
    [[0, 6, 9, 15, 18], [1, 7, 14, 20], [3, 19], [4, 10, 24], [5, 13], [11, 22], [12, 16, 17]],
    [[1, 12, 15, 20], [2, 4, 6, 14, 22], [5, 10, 18, 19, 21], [7, 9, 13, 16], [8, 11]],
    [[0, 17], [1, 4, 16, 20], [2, 19], [3, 5], [8, 14], [10, 18], [11, 15], [12, 13]],
    [[0, 4], [1, 2, 6, 7, 13], [5, 10]],
    [[0, 4, 15, 18], [1, 6, 16], [2, 5, 9, 22], [3, 10, 24, 25], [8, 13, 28], [12, 14, 17, 21], [20, 23]],
    [[0, 3, 13], [1, 9, 11], [4, 6, 10, 12, 21], [5, 18], [7, 14, 15]],
    [[0, 8, 9], [1, 3, 5], [2, 4, 6, 12], [7, 10, 11]],
    [[0, 17], [1, 9, 12], [5, 11], [6, 13, 20, 22], [19, 21]],
    [[2, 3]],
    [[0, 7], [1, 17], [2, 11], [3, 6, 12, 15], [4, 9, 18], [5, 10], [13, 14]],
    [[1, 10], [2, 9, 16, 25], [3, 6], [4, 13, 17], [5, 15, 20, 26], [12, 14, 19]],
    [[1, 2, 3, 5]],
    [[0, 10, 18, 28], [2, 13], [3, 23], [6, 7, 15], [11, 25], [12, 20, 24], [14, 22], [19, 21, 27]],
    [[4, 7, 9, 11], [6, 12], [8, 13, 14], [10, 15]],
    [[0, 5], [2, 4], [3, 9], [6, 13, 21], [8, 11, 14], [18, 22]],
    [[0, 4, 7, 17], [2, 14, 19, 24], [3, 5, 11, 16, 23], [6, 15, 26], [10, 18, 20]],
    [[1, 11], [3, 10, 16], [4, 13, 18], [5, 9], [6, 8, 12, 14], [7, 15, 17]],
    [[0, 20], [1, 13], [2, 3, 19, 25, 26], [4, 11, 22], [5, 10, 12, 17, 18], [9, 21], [15, 24]],
    [[0, 1, 3], [2, 5, 6, 9], [4, 7]],
    [[1, 20], [2, 11, 22], [3, 8, 15, 19], [4, 5, 18], [6, 14], [7, 12, 13, 16], [10, 21]],
    [[0, 2]],
]


def random_scene(seed: int) -> tuple[list[complex], list[complex], list[float]]:
    """2-30 people about 1.2 m apart, random facings (15 % unknown), half of them with a doubtful facing."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 31))
    side = 1.2 * math.sqrt(n)
    positions = rng.uniform(0, side, n) + 1j * rng.uniform(0, side, n)
    facing = np.exp(1j * rng.uniform(-math.pi, math.pi, n))
    facing[rng.random(n) < 0.15] = complex(np.nan, np.nan)
    weight = np.where(rng.random(n) < 0.5, 1.0, 0.5 + 0.5 * rng.random(n))
    return positions.tolist(), facing.tolist(), weight.tolist()


@pytest.mark.parametrize("seed", range(len(EXPECTED_MEMBERS)))
def test_random_scenes_give_the_recorded_groups(seed: int) -> None:
    assert [g.members.tolist() for g in find_ospaces(*random_scene(seed), MODEL)] == EXPECTED_MEMBERS[seed]


@pytest.mark.parametrize("small", [False, True])
def test_a_close_pair_proposes_its_midpoint_where_the_proposals_ahead_miss(small: bool, monkeypatch) -> None:
    # Side by side 1.37 m apart, both facing +y, cones of 45 degrees (facings quantised to 90): the proposals
    # ahead of each lie 0.3-0.8 m in front, far from any centre both cones hold; their midpoint is in both cones.
    monkeypatch.setattr(ospace, "_SMALL_PEOPLE_MAX", 1000 if small else 0)
    scene = inputs([(0.0, 0.0, math.pi / 2), (1.37, 0.0, math.pi / 2)])
    cones = [math.pi / 4] * 2
    assert find_ospaces(*scene, MODEL, cones) == []
    [group] = find_ospaces(*scene, PAIRS, cones)
    assert group.members.tolist() == [0, 1]
    assert group.centre.real == pytest.approx(0.685) and group.centre.imag > 0  # between them, in front of both
    farther = inputs([(0.0, 0.0, math.pi / 2), (3.2, 0.0, math.pi / 2)])  # beyond pair_reach: no pair proposal
    assert find_ospaces(*farther, PAIRS, cones) == []
    # Back to back 0.6 m apart: neither faces the other, so no pair proposal, and no group.
    assert find_ospaces(*inputs([(0.0, 0.0, math.pi), (0.6, 0.0, 0.0)]), PAIRS, cones) == []


@pytest.mark.parametrize("angle", [0.0, 0.01, 0.05, 0.3])
def test_a_pair_exactly_at_pair_reach_proposes_whatever_the_rounding(angle: float) -> None:
    # 1.5 m apart: the distance's rounding after a rotation must not decide whether the pair proposes (at 0.01
    # and 0.05 rad the squared distance rounds above 2.25, at 0 and 0.3 it is 2.25 exactly).
    turn = cmath.exp(1j * angle)
    positions = [0j, 1.5 * turn]
    facing = [1j * turn, 1j * turn]
    found = find_ospaces(positions, facing, [1.0, 1.0], PAIRS, [math.pi / 4] * 2)
    assert [g.members.tolist() for g in found] == [[0, 1]]


@pytest.mark.parametrize("small", [False, True])
def test_a_cheap_group_price_opens_no_o_space_of_one(small: bool, monkeypatch) -> None:
    # A price under the alone price makes each person's own proposal worth opening for them alone; such an o-space
    # dissolves (a group needs two), and had it opened it would have kept the face-to-face pair apart.
    monkeypatch.setattr(ospace, "_SMALL_PEOPLE_MAX", 1000 if small else 0)
    cheap = GroupParams(group_price=0.01).ospace_model
    [group] = find_ospaces(*inputs([(2.0, 0.0, 0.0), (2.8, 0.0, math.pi)]), cheap)
    assert group.members.tolist() == [0, 1] and group.centre == pytest.approx(2.4 + 0j)


@pytest.mark.parametrize("small", [False, True])
def test_people_without_facing_form_no_group_of_their_own(small: bool, monkeypatch) -> None:
    monkeypatch.setattr(ospace, "_SMALL_PEOPLE_MAX", 1000 if small else 0)
    # Two without facing 0.8 m apart, the third 2 m away looking elsewhere: nobody with a known facing in between.
    assert find_ospaces(*inputs([(0.0, 0.0, None), (0.8, 0.0, None), (0.4, 2.0, math.pi / 2)]), MODEL) == []
    # Someone facing them from 0.5 m makes the three a group: an o-space needs one known facing among its members.
    [group] = find_ospaces(*inputs([(0.0, 0.0, None), (0.8, 0.0, None), (0.4, 0.5, -math.pi / 2)]), MODEL)
    assert group.members.tolist() == [0, 1, 2]


@pytest.mark.parametrize("small", [False, True])
def test_a_partner_without_facing_on_the_circle_makes_a_pair(small: bool, monkeypatch) -> None:
    # One person faces a partner 0.8 m ahead whose facing is unknown (half hidden behind them): the partner stands
    # on the circle of the first one's proposals, within unknown_tolerance, and counts towards opening it.
    monkeypatch.setattr(ospace, "_SMALL_PEOPLE_MAX", 1000 if small else 0)
    [group] = find_ospaces(*inputs([(0.0, 0.0, 0.0), (0.8, 0.0, None)]), MODEL)
    assert group.members.tolist() == [0, 1]
    # A partner 0.48 m or more off every circle the first one proposes (as the seated person of the real frame
    # hero_12-42-25, 1.2 m to the side of someone facing the robot): no pair, though joining a group would be cheap.
    assert find_ospaces(*inputs([(0.0, 0.0, 0.0), (0.35, 1.2, None)]), MODEL) == []
    # A partner a little off the circle pairs with the default tolerance, not with none (exactly on it, within TIE).
    near = inputs([(0.0, 0.0, 0.0), (0.9, 0.3, None)])
    assert [g.members.tolist() for g in find_ospaces(*near, MODEL)] == [[0, 1]]
    assert find_ospaces(*near, dataclasses.replace(MODEL, unknown_tolerance=0.0)) == []


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("radius_min", -0.1),
        ("radius_max", 0.2),
        ("radius_steps", 1.5),
        ("price", float("inf")),
        ("body_radius", -1),
        ("alone_price", 0.0),
        ("angular_weight", -1.0),
        ("pair_reach", -0.5),
        ("pair_reach", math.inf),
    ],
)
def test_bad_constants_are_refused_by_name(field, value):
    values = {"radius_min": 0.3, "radius_max": 0.8, "radius_steps": 4, "price": 0.65, "unknown_cost": 0.5}
    values |= {"alone_price": 0.65, "angular_weight": 0.35}
    with pytest.raises(ValueError, match=f"ospace: {field}"):
        OSpaceModel(**(values | {"body_radius": 0.1, field: value}))


def test_reach_squared_is_the_exact_threshold_of_the_rounded_root():
    for model in (MODEL, GroupParams(radius_max=0.9, group_price=0.7).ospace_model):
        bound = model.reach_squared
        assert math.sqrt(bound) >= model.reach > math.sqrt(math.nextafter(bound, 0.0))


@pytest.mark.parametrize("seed", range(40))
@pytest.mark.parametrize("model", [MODEL, PAIRS], ids=["own proposals", "pair proposals"])
def test_the_small_path_matches_a_direct_transcription_of_the_crowd_rules(seed: int, model: OSpaceModel) -> None:
    # Rows and greedy passes written out plainly (no shortcuts: every row in every pass, every neighbour tested),
    # on scenes small enough for the small path, with ties from a coarse grid in half of them.
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 17))
    if seed % 2:  # a 0.6 m grid, facings in steps of 45 degrees
        cells = rng.choice(25, n, replace=False)
        positions = [complex(0.6 * (c % 5), 0.6 * (c // 5)) for c in cells]
        angles = rng.integers(0, 8, n) * math.pi / 4
    else:
        positions = (rng.uniform(0, 1.2 * math.sqrt(n), n) + 1j * rng.uniform(0, 1.2 * math.sqrt(n), n)).tolist()
        angles = rng.uniform(-math.pi, math.pi, n)
    facing = [complex(math.cos(a), math.sin(a)) if rng.random() > 0.15 else complex(math.nan, math.nan) for a in angles]
    weight = rng.choice([1.0, 0.5, 0.75], n).tolist()
    slack = [float(rng.choice([0.0, 0.4, math.pi / 4]))] * n
    found = find_ospaces(positions, facing, weight, model, slack)
    expected = plain_search(positions, facing, weight, slack, model)
    assert [(g.members.tolist(), g.centre, g.radius) for g in found] == expected


def plain_search(positions, facing, weight, slack, model) -> list[tuple[list[int], complex, float]]:
    """The small path's rounds with the rows and passes computed without any shortcut."""
    known = [not cmath.isnan(f) for f in facing]
    owners = [j for j, k in enumerate(known) if k]
    if not owners or len(positions) < 2:
        return []
    facing = [f if k else 0j for f, k in zip(facing, known, strict=True)]
    people = [
        (p.real, p.imag, f.real, f.imag, w if k else 0.0, math.cos(s) if k else 1.0, math.sin(s) if k else 0.0)
        for p, f, w, s, k in zip(positions, facing, weight, slack, known, strict=True)
    ]
    radii = model.radii.tolist()
    first = [(positions[o] + r * facing[o], r) for o in owners for r in radii]
    first_owner = [(o, o) for o in owners for _ in radii]
    for a, b in itertools.combinations(owners, 2):  # pairs at most pair_reach apart (TIE above it) propose too,
        distance = abs(positions[b] - positions[a])  # unless one faces more than 90 degrees away from the other
        towards = [
            cmath.phase((positions[b] - positions[a]) / facing[a]),
            cmath.phase((positions[a] - positions[b]) / facing[b]),
        ]
        if distance <= model.pair_reach * (1 + 1e-9) and max(map(abs, towards)) <= math.pi / 2 + 1e-9:
            first.append(
                ((positions[a] + positions[b]) / 2, min(max(distance / 2, model.radius_min), model.radius_max))
            )
            first_owner.append((a, b))
    candidates, labels = first, []
    for _ in range(8):
        previous = labels
        rows = [plain_row(centre, radius, people, model) for centre, radius in candidates]
        labels, behind = ospace._canonical(plain_assign(rows, known, model), known)
        fitted = ospace._refit_small(labels, people, [candidates[k] for k in behind], model)
        if labels == previous:
            break
        candidates = fitted + [first[k] for k, (a, b) in enumerate(first_owner) if min(labels[a], labels[b]) < 0]
    return [
        ([j for j, label in enumerate(labels) if label == g], centre, radius)
        for g, (centre, radius) in enumerate(fitted)
    ]


def plain_row(centre, radius, people, model) -> list[tuple[int, float]]:
    """(person, cost) of everyone who may join the candidate (centre, radius): within reach by the rounded root,
    under the alone price by the general cost formula (the facing's angle phi from the centre and its slack s,
    by their cosines), and nobody listed in the way (every other person tested); thresholds within TIE."""
    tie = ospace.TIE
    offsets = [(centre.real - x, centre.imag - y) for x, y, *_ in people]
    listed = [math.sqrt(ox * ox + oy * oy) < model.reach for ox, oy in offsets]
    row = []
    for j, (px, py, fx, fy, w, cos_s, sin_s) in enumerate(people):
        ox, oy = centre.real - px, centre.imag - py
        length2 = ox * ox + oy * oy
        if not listed[j]:
            continue
        rho = math.sqrt(length2)
        cos_phi = (ox * fx + oy * fy) / rho if rho else 1.0
        sin_phi = abs(ox * fy - oy * fx) / rho if rho else 0.0
        outside = cos_phi < cos_s  # the centre lies outside the facing's cone
        angular = 2 * radius * rho * (1 - (cos_phi * cos_s + sin_phi * sin_s)) if outside else 0.0
        on_circle = (rho - radius) ** 2
        cost = w * (on_circle + model.angular_weight * angular) + (1.0 - w) * (on_circle + model.unknown_cost**2)
        blocked = False
        for b, (bx, by, *_) in enumerate(people):
            rx, ry = bx - px, by - py
            dot, cross = rx * ox + ry * oy, rx * oy - ry * ox
            between = tie * length2 < dot < (1 - tie) * length2
            if b != j and listed[b] and between and cross * cross < (1 - tie) * model.body_radius**2 * length2:
                blocked = True
        if cost < model.alone_price * (1 - tie) and not blocked:
            row.append((j, cost))
    return row


def plain_assign(rows, known, model) -> list[int]:
    """The greedy passes as the small path first wrote them: every row's saving and favourites in every pass;
    gains, savings and costs within TIE of the alone price count as equal, and the lowest candidate wins ties."""
    tie = ospace.TIE * model.alone_price
    current, opened = [model.alone_price] * len(known), [False] * len(rows)
    # unknown facings count towards opening within unknown_tolerance of the circle (opening_cost, TIE included)
    openers = [[(j, c) for j, c in row if known[j] or c <= model.opening_cost] for row in rows]
    while True:
        savings = []
        for row in openers:
            total = 0.0
            for j, c in row:
                if c < current[j] - tie:
                    total += current[j] - c
            gaining = [j for j, c in row if c < current[j] - tie]  # fewer than two: an o-space of one, no saving
            facing = any(known[j] for j in gaining)  # and one of them with a known facing
            savings.append(total - model.price if len(gaining) >= 2 and facing else -math.inf)
        if max(savings) <= tie:
            break
        best = [
            max(
                (savings[k] for k, row in enumerate(openers) for i, c in row if i == j and c < current[j] - tie),
                default=-math.inf,
            )
            for j in range(len(known))
        ]
        favourite = [
            min(
                (
                    k
                    for k, row in enumerate(openers)
                    for i, c in row
                    if i == j and c < current[j] - tie and savings[k] >= best[j] - tie
                ),
                default=-1,
            )
            for j in range(len(known))
        ]
        accepted = [
            k
            for k, row in enumerate(openers)
            if savings[k] > tie and all(favourite[j] == k or c >= current[j] - tie for j, c in row)
        ]
        for k in accepted:
            opened[k] = True
            for j, c in openers[k]:
                current[j] = min(current[j], c)
    cheapest = [
        min((c for k, row in enumerate(rows) if opened[k] for i, c in row if i == j), default=math.inf)
        for j in range(len(known))
    ]
    return [
        min(
            (k for k, row in enumerate(rows) if opened[k] for i, c in row if i == j and c <= cheapest[j] + tie),
            default=-1,
        )
        for j in range(len(known))
    ]

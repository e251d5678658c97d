"""The tracked-people layer: standing people as the social layer, walkers stretched ahead, zones of tracked groups."""

from __future__ import annotations

import math

import numpy as np
import pytest

from costmap.grid import FREE_SPACE, LETHAL, GridSpec
from costmap.layer import LayerInputs
from costmap.layers.social import GROUPS, PEOPLE, SocialLayer, SocialParams
from costmap.layers.tracked import TRACKS, TrackedPeopleLayer, TrackedPeopleParams
from costmap.plugins import CostmapParams, layered_costmap
from sid.perception.group import Group
from sid.perception.people import Person
from sid.tracking import TrackedGroup, TrackedPerson, Tracks

SPEC = GridSpec.from_size(0.05, (-1.0, -4.0), (10.0, 8.0))


def _track(track_id: int, x: float, y: float, theta: float | None, v: tuple[float, float] = (0.0, 0.0)):
    state = "walking" if math.hypot(*v) > 0.5 else "standing"
    return TrackedPerson(
        track_id, x, y, v[0], v[1], theta, state, True, True, 0.0, None, 0.1, 0.0 if theta is None else 1.0
    )


def _cost(layer: TrackedPeopleLayer | SocialLayer, x: float, y: float) -> int:
    (row, col) = SPEC.world_to_cell(np.array([x, y]))[0]
    return int(layer.costs[row, col])


def test_standing_people_and_their_group_cost_what_the_social_layer_draws() -> None:
    angles = np.deg2rad([90, 210, 330])
    tracks = [_track(i + 7, 4 + 0.6 * np.cos(a), 0.6 * np.sin(a), float(a + np.pi)) for i, a in enumerate(angles)]
    zone = np.array([[4.0, 0.2], [3.83, -0.1], [4.17, -0.1]])
    group = TrackedGroup(3, "conversation", (7, 8, 9), (4.0, 0.0), zone, 0.05, 0.6, (0.0, 0.0), 0.0)
    tracked = TrackedPeopleLayer(SPEC)
    tracked.update(LayerInputs({TRACKS: Tracks(tracks, [group])}), None)
    social = SocialLayer(SPEC)
    people = [Person(t.id, t.x, t.y, t.theta, 1.0) for t in tracks]
    social.update(LayerInputs({PEOPLE: people, GROUPS: [Group((7, 8, 9), (4.0, 0.0), 0.05, zone, 0.6)]}), None)
    np.testing.assert_array_equal(tracked.costs, social.costs)
    assert _cost(tracked, 4.0, 0.0) == 240
    people_only = TrackedPeopleLayer(SPEC)  # the zone is drawn: without the group the centre costs less
    people_only.update(LayerInputs({TRACKS: Tracks(tracks, [])}), None)
    assert _cost(people_only, 4.0, 0.0) < 240
    assert np.count_nonzero(tracked.costs > people_only.costs) > 1000


def test_a_walker_costs_more_ahead_than_behind_and_than_standing() -> None:
    walking, standing = TrackedPeopleLayer(SPEC), TrackedPeopleLayer(SPEC)
    walking.update(LayerInputs({TRACKS: Tracks([_track(1, 4.0, 0.0, math.pi / 2, (1.3, 0.0))])}), None)
    standing.update(LayerInputs({TRACKS: Tracks([_track(1, 4.0, 0.0, 0.0)])}), None)
    for ahead in (0.8, 1.5, 2.5):  # along the velocity (+x), whatever the facing (+y)
        assert _cost(walking, 4.0 + ahead, 0.0) > _cost(standing, 4.0 + ahead, 0.0)
        assert _cost(walking, 4.0 + ahead, 0.0) > _cost(walking, 4.0 - ahead, 0.0)
    assert _cost(walking, 4.0, 0.0) == LETHAL
    far = TrackedPeopleLayer(SPEC)  # the cost reaches (sigma_front + lookahead * speed) * sqrt(2 ln 200) ahead
    far.update(LayerInputs({TRACKS: Tracks([_track(1, 0.0, 0.0, None, (1.3, 0.0))])}), None)
    reach = (0.8 + 1.0 * 1.3) * math.sqrt(2 * math.log(200))
    assert _cost(far, reach - 0.1, 0.0) > 0 and _cost(far, reach + 0.1, 0.0) == 0
    longer = TrackedPeopleLayer(SPEC, TrackedPeopleParams(lookahead=2.0))
    longer.update(LayerInputs({TRACKS: Tracks([_track(1, 4.0, 0.0, None, (1.3, 0.0))])}), None)
    assert _cost(longer, 6.5, 0.0) > _cost(walking, 6.5, 0.0)


def test_walking_groups_get_no_zone() -> None:
    v = (1.2, 0.0)
    tracks = [_track(1, 4.0, 0.4, -math.pi / 2, v), _track(2, 4.0, -0.4, math.pi / 2, v)]
    group = TrackedGroup(1, "walking", (1, 2), (4.0, 0.0), np.zeros((0, 2)), 0.0, 0.4, v, 0.0)
    with_group, without = TrackedPeopleLayer(SPEC), TrackedPeopleLayer(SPEC)
    with_group.update(LayerInputs({TRACKS: Tracks(tracks, [group])}), None)
    without.update(LayerInputs({TRACKS: Tracks(tracks)}), None)
    np.testing.assert_array_equal(with_group.costs, without.costs)


def test_the_layer_is_cleared_when_the_tracks_go() -> None:
    layer = TrackedPeopleLayer(SPEC)
    layer.update(LayerInputs({TRACKS: Tracks([_track(1, 4.0, 0.0, 0.0)])}), None)
    assert layer.costs.any()
    window = layer.update(LayerInputs(), None)
    assert window is not None and not layer.costs.any()
    assert layer.update(LayerInputs(), None) is None
    assert (layer.costs == FREE_SPACE).all()


def test_tracks_must_hold_every_group_member() -> None:
    group = TrackedGroup(1, "conversation", (1, 2), (4.0, 0.0), np.zeros((1, 2)), 0.0, 0.4, (0.0, 0.0), 0.0)
    with pytest.raises(ValueError, match=r"group 1 has members \[2\]"):
        Tracks([_track(1, 4.0, 0.0, 0.0)], [group])


def test_the_plugin_builds_the_layer_and_clears_lidar_marks_around_people() -> None:
    layered = layered_costmap(SPEC, CostmapParams(plugins=("lidar", "tracked_people", "inflation")))
    assert isinstance(layered.layer("tracked_people"), TrackedPeopleLayer)
    track = _track(1, 4.0, 0.0, 0.0)
    layered.update(LayerInputs({PEOPLE: [track.as_person()], TRACKS: Tracks([track])}))
    (row, col) = SPEC.world_to_cell(np.array([4.0, 0.0]))[0]
    assert layered.master.costs[row, col] == LETHAL


def test_the_costmap_parameters_reach_the_tracked_layer() -> None:
    params = CostmapParams(
        plugins=("tracked_people",), social=SocialParams(sigma_front=0.5), tracked_people=TrackedPeopleParams(2.0)
    )
    (layer,) = layered_costmap(SPEC, params).layers
    assert isinstance(layer, TrackedPeopleLayer)
    assert layer.params.lookahead == 2.0 and layer.social.sigma_front == 0.5

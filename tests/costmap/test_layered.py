"""The layered costmap: windowed updates against a full recombination, windows far apart, people updates with and
without the social layer, the inputs its layers read."""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from costmap.grid import LETHAL, NO_INFORMATION, GridSpec, union
from costmap.layer import Input, LayerInputs
from costmap.layered import LayeredCostmap
from costmap.layers.inflation import InflationLayer, InflationParams
from costmap.layers.obstacle import SCAN, ObstacleParams
from costmap.layers.social import GROUPS, PEOPLE, group_zone_polygon
from costmap.layers.tracked import TRACKS
from costmap.plugins import CostmapParams, layered_costmap
from sid.perception.group import Group
from sid.perception.groups import detect_groups
from sid.perception.people import Person
from sid.scenario.lidar import simulate_scan
from sid.scenario.obstacles import CircleObstacle, SegmentObstacle
from tests.costmap.scenes import frames, triad

SPEC = GridSpec.from_size(0.05, (-1.0, -4.0), (10.0, 8.0))


def test_a_windowed_update_gives_the_master_a_full_recombination_gives():
    for params in (CostmapParams(), CostmapParams(obstacle=ObstacleParams(track_unknown_space=True)).without("social")):
        layered = layered_costmap(SPEC, params)
        windows = []
        for inputs in frames():
            windows.append(layered.update(inputs))
            full = np.full(SPEC.shape, layered.default_value, dtype=np.uint8)
            for layer in layered.layers:
                layer.write(full, SPEC.whole)
            np.testing.assert_array_equal(layered.master.costs, full)
        if "social" in params.plugins:  # frame 2 has no scan: only the cells around the people change
            assert windows[2] is not None and windows[2] != SPEC.whole
        else:  # people are plain LiDAR marks: without a scan nothing changes
            assert windows[2] is None


def far_apart_frames() -> list[LayerInputs]:
    """Three groups 20-37 m apart on a 40 m map (so their windows are written apart), walking; one leaves, and a
    scan from a sensor that moves comes every other frame."""
    centres = [(-13.0, -13.0), (13.0, 13.0), (6.0, -6.0)]
    walls = [SegmentObstacle(((-19.0, -19.0), (19.0, -19.0), (19.0, 19.0))), CircleObstacle((0.0, 3.0), 0.5)]
    out = []
    for step in range(6):
        people = []
        for k, (cx, cy) in enumerate(centres[: 3 - step // 4]):
            for j, angle in enumerate(np.linspace(0.0, 2 * np.pi, 3, endpoint=False) + 0.3):
                x, y = cx + 0.7 * np.cos(angle) + 0.05 * step, cy + 0.7 * np.sin(angle)
                people.append(Person(10 * k + j, x, y, float(angle + np.pi)))
        pose = (0.02 * step + (0.3 if step == 3 else 0.0), 0.0, 0.0)
        scan = simulate_scan(pose, walls, people, beams=360, range_max=25.0) if step % 2 == 0 else None
        out.append(LayerInputs({PEOPLE: people, GROUPS: detect_groups(people), SCAN: scan}))
    return out


def test_windows_far_apart_are_written_apart_with_the_master_one_box_gives(monkeypatch):
    import costmap.layered

    spec = GridSpec.from_size(0.05, (-20.0, -20.0), (40.0, 40.0))
    params = CostmapParams(obstacle=ObstacleParams(raytrace_max_range=25.0, obstacle_max_range=25.0))
    apart, one_box = layered_costmap(spec, params), layered_costmap(spec, params)
    counts = []
    for inputs in far_apart_frames():
        window = apart.update(inputs)
        with monkeypatch.context() as patch:  # Nav2's one box: every window merged
            patch.setattr(costmap.layered, "disjoint", lambda windows: [w for w in [union(*windows)] if w])
            assert one_box.update(inputs) == window  # the same bounds reported
        counts.append(len(apart.windows))
        np.testing.assert_array_equal(apart.master.costs, one_box.master.costs)
        for name, grid in apart.grids.items():
            np.testing.assert_array_equal(grid, one_box.grids[name], err_msg=name)
        full = np.full(spec.shape, apart.default_value, dtype=np.uint8)
        for layer in apart.layers:
            layer.write(full, spec.whole)
        np.testing.assert_array_equal(apart.master.costs, full)
    assert counts[1::2] == [3, 3, 2]  # frames without a scan: a window per group (a scan's spans them)


def social_costmap(social: bool = True) -> LayeredCostmap:
    """The default layers on SPEC (no static map), with or without the social layer."""
    return layered_costmap(SPEC, CostmapParams() if social else CostmapParams().without("social"))


def scan_of(people, pose=(0.0, 0.0, 0.0)):
    return simulate_scan(pose, [SegmentObstacle(((-1.0, 2.5), (9.0, 2.5)))], people, beams=720, range_max=10.0)


def lethal_near(costs: np.ndarray, xy, radius: float) -> int:
    xs, ys = SPEC.cell_centres()
    return int(((np.hypot(xs - xy[0], ys - xy[1]) <= radius) & (costs == LETHAL)).sum())


def test_without_social_layer_only_lidar_marks_and_their_inflation_remain():
    people, group = triad()
    layered = social_costmap(social=False)
    layered.update(LayerInputs({PEOPLE: people, GROUPS: [group], SCAN: scan_of(people)}))
    assert set(layered.grids) == {"lidar", "inflation"}
    expected = layered.grids["lidar"].copy()
    InflationLayer(SPEC, InflationParams(), inscribed_radius=0.25).write(expected, SPEC.whole)
    np.testing.assert_array_equal(layered.master.costs, expected)
    assert layered.master.cost_at([group.interest_point])[0] < 240  # the o-space is not protected


def test_with_social_layer_the_group_zone_is_high_cost_in_the_master():
    people, group = triad()
    layered = social_costmap()
    layered.update(LayerInputs({PEOPLE: people, GROUPS: [group], SCAN: scan_of(people)}))
    xs, ys = SPEC.cell_centres()
    inside = shapely.contains_xy(group_zone_polygon(group, people), xs, ys)
    assert (layered.master.costs[inside] >= 240).all()
    # between two members, where the baseline lets the robot through
    a, b = people[1], people[2]
    assert layered.master.cost_at([[(a.x + b.x) / 2, (a.y + b.y) / 2]])[0] >= 240


def test_a_moved_person_leaves_no_stale_marks_with_or_without_a_new_scan():
    old = [Person(1, 4.0, 0.0, np.pi)]
    new = [Person(1, 4.0, 1.5, np.pi)]
    for new_scan in (None, scan_of(new)):
        layered = social_costmap()
        layered.update(LayerInputs({PEOPLE: old, SCAN: scan_of(old)}))
        assert lethal_near(layered.master.costs, (4.0, 0.0), 0.3) > 0
        layered.update(LayerInputs({PEOPLE: new, SCAN: new_scan}))
        assert lethal_near(layered.master.costs, (4.0, 0.0), 0.3) == 0
        assert lethal_near(layered.grids["lidar"], (4.0, 1.5), 0.3) == 0  # the person is the social layer's, once
        assert lethal_near(layered.master.costs, (4.0, 1.5), 0.2) > 0
        assert layered.master.cost_at([[4.0, 0.0]])[0] < 50  # only the new position's fading personal space


def test_baseline_keeps_people_marks_where_no_new_beam_passes():
    old = [Person(1, 4.0, 0.0, np.pi)]
    layered = social_costmap(social=False)
    layered.update(LayerInputs({PEOPLE: old, SCAN: scan_of(old)}))
    layered.update(LayerInputs({PEOPLE: [Person(1, 4.0, 1.5, np.pi)]}))
    assert lethal_near(layered.master.costs, (4.0, 0.0), 0.3) > 0  # Nav2 behaviour without recognition


def test_something_left_at_a_person_old_position_is_kept_when_the_scan_sees_it():
    old = [Person(1, 4.0, 0.0, np.pi)]
    layered = social_costmap()
    layered.update(LayerInputs({PEOPLE: old, SCAN: scan_of(old)}))
    pillar = simulate_scan((0.0, 0.0, 0.0), [CircleObstacle((4.0, 0.0), 0.2)], [], beams=720)
    layered.update(LayerInputs({PEOPLE: [Person(1, 4.0, 1.5, np.pi)], SCAN: pillar}))
    assert lethal_near(layered.master.costs, (4.0, 0.0), 0.3) > 0


def test_update_rejects_nan_people_duplicate_ids_and_a_sensor_off_the_map_before_changing_anything():
    layered = social_costmap()
    layered.update(LayerInputs({PEOPLE: [Person(1, 4.0, 0.0)], SCAN: scan_of([Person(1, 4.0, 0.0)])}))
    before = {"master": layered.master.costs.copy()} | {k: v.copy() for k, v in layered.grids.items()}
    with pytest.raises(ValueError, match="outside the costmap"):
        layered.update(LayerInputs({PEOPLE: [Person(1, 5.0, 0.0)], SCAN: scan_of([], pose=(20.0, 0.0, 0.0))}))
    after = {"master": layered.master.costs} | layered.grids
    for name, grid in before.items():
        np.testing.assert_array_equal(after[name], grid, err_msg=name)
    with pytest.raises(ValueError, match=r"members \[7\]"):  # the social layer refuses; the master waits
        layered.update(
            LayerInputs(
                {PEOPLE: [Person(1, 5.0, 0.0)], GROUPS: [Group((1, 7), (5.0, 0.5), 0.0, np.zeros((0, 2)), 0.5)]}
            )
        )
    np.testing.assert_array_equal(layered.master.costs, before["master"])
    np.testing.assert_array_equal(layered.grids["social"], before["social"])
    assert layered.inputs[PEOPLE] == (Person(1, 4.0, 0.0),)
    with pytest.raises(ValueError, match="person 3"):
        layered.update(LayerInputs({PEOPLE: [Person(3, np.nan, 0.0)]}))
    with pytest.raises(ValueError, match="twice"):
        layered.update(LayerInputs({PEOPLE: [Person(1, 0.0, 0.0), Person(1, 1.0, 0.0)]}))


def test_unknown_space_stays_unknown_around_people_when_tracked():
    spec = GridSpec(0.05, 0.0, 0.0, 100, 100)
    layered = layered_costmap(spec, CostmapParams(obstacle=ObstacleParams(track_unknown_space=True)))
    layered.update(LayerInputs({PEOPLE: [Person(1, 2.5, 2.5, 0.0)]}))  # no scan: all unknown but the social costs
    costs = layered.master.costs
    assert costs[0, 0] == NO_INFORMATION
    assert costs[50, 50] == LETHAL and costs[50, 62] not in (0, NO_INFORMATION)


def test_a_costmap_reads_what_its_layers_read_and_refuses_a_stranger_named_as_one_of_them():
    assert layered_costmap(SPEC).reads == (SCAN, PEOPLE, GROUPS)  # static and inflation read no input
    assert layered_costmap(SPEC, CostmapParams(plugins=("tracked_people", "inflation"))).reads == (TRACKS,)
    people, group = triad()
    layered = social_costmap()
    layered.update(LayerInputs({PEOPLE: people, GROUPS: [group]}))
    before = layered.master.costs.copy()
    stranger = Input("people", ())  # another key of the same name: the layers would never see its people
    with pytest.raises(ValueError, match=r"inputs \['people'\]: not the keys"):
        layered.update(LayerInputs({stranger: [Person(9, 1.0, 1.0)]}))
    np.testing.assert_array_equal(layered.master.costs, before)
    assert layered.inputs[GROUPS] == (group,)
    layered.update(LayerInputs({Input("doorways", ()): [(1.0, 1.0)]}))  # read by no layer: kept, nothing to paint
    assert not (layered.master.costs > 0).any()

"""The layer interface: windows, the ordered layer list, combination methods and the plugin configuration."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from costmap.grid import FREE_SPACE, INSCRIBED, LETHAL, NO_INFORMATION, GridSpec, Window, union
from costmap.layer import Layer, LayerInputs
from costmap.layered import LayeredCostmap
from costmap.layers.inflation import InflationLayer, InflationParams
from costmap.layers.obstacle import ObstacleLayer, ObstacleParams
from costmap.occupancy import OccupancyGrid
from costmap.plugins import PLUGINS, CostmapParams, layered_costmap
from sid.perception.groups import detect_groups
from sid.perception.people import Person
from sid.scenario.lidar import simulate_scan
from sid.scenario.obstacles import CircleObstacle, SegmentObstacle

SPEC = GridSpec.from_size(0.05, (-1.0, -4.0), (10.0, 8.0))
WALLS = [SegmentObstacle(((-1.0, 2.5), (9.0, 2.5))), CircleObstacle((6.0, -2.0), 0.3)]


def frames() -> list[LayerInputs]:
    """People who walk, leave and arrive, with a scan in some frames only (from a robot that moves)."""
    people = [Person(1, 4.0, 0.0, np.pi), Person(2, 4.6, 0.5, -2.0), Person(3, 4.6, -0.5, 2.0), Person(4, 2.0, -2.0)]
    out = []
    for step in range(6):
        moved = [Person(p.id, p.x + 0.2 * step, p.y - 0.1 * step, p.theta) for p in people[: 4 - step // 3]]
        scan = None if step in (2, 4) else simulate_scan((0.3 * step, 0.0, 0.0), WALLS, moved, beams=360)
        out.append(LayerInputs(moved, detect_groups(moved), scan))
    return out


class Fence(Layer):
    """A lethal line at x = 6 m, drawn once."""

    name = "fence"
    combination = "max"

    def update(self, inputs: LayerInputs, changed: Window | None) -> Window | None:
        if self.costs.any():
            return None
        window = self.spec.window((6.0, -4.0), (6.0, 4.0))
        assert window is not None
        self.costs[window.slices] = LETHAL
        return window


class Unknown(Layer):
    """A 1 m square of unknown cells around (2, 2), with the combination method it is given."""

    name = "unknown"

    def __init__(self, spec: GridSpec, combination: str) -> None:
        self.combination = combination
        super().__init__(spec)

    def update(self, inputs: LayerInputs, changed: Window | None) -> Window | None:
        window = self.spec.window((1.5, 1.5), (2.45, 2.45))
        assert window is not None
        self.costs[window.slices] = NO_INFORMATION
        return window


def test_windows_union_grow_and_clip():
    a, b = Window(2, 5, 3, 4), Window(4, 9, 0, 2)
    assert a.union(b) == union(None, a, None, b) == Window(2, 9, 0, 4)
    assert union(None, None) is None and a.union(None) == a
    assert Window(1, 3, 1, 3).grown(2, SPEC) == Window(0, 5, 0, 5)
    assert SPEC.whole.grown(3, SPEC) == SPEC.whole == Window(0, 160, 0, 200)
    assert Window(-5, 2, 190, 300).clipped(SPEC) == Window(0, 2, 190, 200)
    assert Window(-5, 0, 0, 3).clipped(SPEC) is None
    assert SPEC.window((20.0, 0.0), (21.0, 1.0)) is None
    assert SPEC.window((np.nan, 0.0), (1.0, 1.0)) is None and SPEC.window((0.0, 0.0), (np.inf, 1.0)) is None
    assert SPEC.window_around([[0.0, 0.0], [-0.96, 0.07]]) == Window(80, 82, 0, 21)
    assert SPEC.window_around(np.zeros((0, 2))) is None
    costs = np.zeros(SPEC.shape)
    costs[Window(1, 3, 4, 7).slices] = 1
    assert costs.sum() == 6


def test_every_layer_changes_only_cells_inside_the_windows_it_reports():
    layered = layered_costmap(SPEC)
    reported: dict[str, list[Window]] = {}
    for layer in layered.layers:  # record what each layer reports
        update = layer.update_windows

        def spy(inputs, changed, update=update, name=layer.name):
            reported[name] = update(inputs, changed)
            return reported[name]

        layer.update_windows = spy
    for inputs in frames():
        before = {name: grid.copy() for name, grid in layered.grids.items()}
        master_before = layered.master.costs.copy()
        window = layered.update(inputs)
        assert window == union(*(w for windows in reported.values() for w in windows))
        assert window == union(*layered.windows)
        for a, b in itertools.combinations(layered.windows, 2):
            assert not a.overlaps(b)
        for name, grid in layered.grids.items():
            changed = grid != before[name]
            for part in reported[name]:
                changed[part.slices] = False
            assert not changed.any(), name
        outside = layered.master.costs != master_before
        for part in layered.windows:
            outside[part.slices] = False
        assert not outside.any()
    social_and_lidar = union(*reported["social"], *reported["lidar"])
    assert social_and_lidar is not None
    assert union(*reported["inflation"]) == social_and_lidar.grown(11, SPEC)


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
        out.append(LayerInputs(people, detect_groups(people), scan))
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


def test_inflation_written_window_by_window_reaches_across_their_edges():
    # A lethal cell that changes near the edge of one window is found by the first window whose reach holds it; the
    # cells within reach of it in the next window must be recomputed then, though that window finds no change.
    master = np.zeros(SPEC.shape, dtype=np.uint8)
    master[60:64, 100:103] = LETHAL
    first, second = Window(40, 80, 60, 96), Window(40, 80, 96, 140)  # the lethal cells lie in the second
    for order in ((first, second), (second, first)):
        layer = InflationLayer(SPEC, InflationParams(), inscribed_radius=0.25)
        full = master.copy()
        InflationLayer(SPEC, InflationParams(), inscribed_radius=0.25).write(full, SPEC.whole)
        part = master.copy()
        for window in order:
            layer.write(part, window)
        for window in order:
            np.testing.assert_array_equal(part[window.slices], full[window.slices])


def test_inflation_over_a_window_reads_the_lethal_cells_within_reach_of_it():
    master = np.zeros(SPEC.shape, dtype=np.uint8)
    master[50, 50] = master[75, 120] = LETHAL  # outside the window, within reach of it
    layer = InflationLayer(SPEC, InflationParams(), inscribed_radius=0.25)
    full = master.copy()
    layer.write(full, SPEC.whole)
    window = Window(53, 70, 40, 130)
    part = master.copy()
    layer.write(part, window)
    np.testing.assert_array_equal(part[window.slices], full[window.slices])
    assert part[window.slices].any()
    part[window.slices] = master[window.slices]
    np.testing.assert_array_equal(part, master)  # nothing written outside the window


def test_a_new_layer_is_one_class_and_one_line_of_configuration():
    inputs = frames()[0]
    plugins = {**PLUGINS, "fence": lambda c: Fence(c.spec)}  # the line of configuration
    plain = layered_costmap(SPEC)
    plain.update(inputs)
    fenced = layered_costmap(SPEC, CostmapParams(plugins=("lidar", "fence", "social", "inflation")), plugins=plugins)
    assert list(fenced.grids) == ["lidar", "fence", "social", "inflation"]
    fence = fenced.spec.window((6.0, -4.0), (6.0, 4.0))
    beside = fenced.spec.world_to_cell([[6.15, 0.0], [5.9, 1.0]])
    assert fenced.update(LayerInputs()) == fence.grown(11, SPEC)  # only the fence changed, and its inflation
    assert (fenced.master.costs[fence.slices] == LETHAL).all()
    assert (fenced.master.costs[beside[:, 0], beside[:, 1]] == INSCRIBED).all()  # inflated: inflation comes later
    fenced.update(inputs)
    differs = fenced.master.costs != plain.master.costs
    differs[fence.grown(11, SPEC).slices] = False
    assert not differs.any()
    late = layered_costmap(SPEC, CostmapParams(plugins=("lidar", "social", "inflation", "fence")), plugins=plugins)
    late.update(inputs)
    assert (late.master.costs[fence.slices] == LETHAL).all()
    assert late.master.costs[beside[0, 0], beside[0, 1]] == plain.master.costs[beside[0, 0], beside[0, 1]] < INSCRIBED
    assert fenced.layer("fence").update(inputs, None) is None  # it changes nothing after its first update


def test_a_layer_writes_with_its_combination_method_in_its_place_in_the_order():
    inputs = LayerInputs([Person(1, 2.0, 2.0, 0.0)])  # no scan: only the person's body and personal space
    square, ahead = SPEC.window((1.5, 1.5), (2.45, 2.45)), [[3.0, 2.0]]

    def build(combination: str, order: tuple[str, ...]) -> LayeredCostmap:
        plugins = {**PLUGINS, "unknown": lambda c: Unknown(c.spec, combination)}
        layered = layered_costmap(SPEC, CostmapParams(plugins=order), plugins=plugins)
        layered.update(inputs)
        return layered

    plain = layered_costmap(SPEC)
    plain.update(inputs)
    assert plain.master.cost_at(ahead)[0] > 0 and LETHAL in plain.master.costs[square.slices]
    before_inflation = ("lidar", "social", "unknown", "inflation")
    # max: unknown layer cells carry no opinion
    np.testing.assert_array_equal(build("max", before_inflation).master.costs, plain.master.costs)
    # overwrite: the layer's free cells replace what came before, its unknown cells do not
    overwrite = build("overwrite", before_inflation).master
    assert overwrite.cost_at(ahead)[0] == FREE_SPACE
    np.testing.assert_array_equal(overwrite.costs[square.slices], plain.master.costs[square.slices])
    # true_overwrite: the layer's grid replaces everything, the body included, so nothing is left to inflate
    true_overwrite = build("true_overwrite", before_inflation)
    np.testing.assert_array_equal(true_overwrite.master.costs, true_overwrite.grids["unknown"])
    # first in the order, the layers after it write over it (Nav2's max overwrites unknown master cells)
    first = build("true_overwrite", ("unknown", "lidar", "social", "inflation"))
    np.testing.assert_array_equal(first.master.costs, plain.master.costs)


def test_the_static_layer_writes_its_map_at_the_first_update_only():
    data = np.zeros(SPEC.shape, dtype=np.int8)
    data[100, :] = 100  # a wall along y = 1.025
    data[:, :10] = -1  # unknown
    params = CostmapParams(obstacle=ObstacleParams(track_unknown_space=True))
    layered = layered_costmap(SPEC, params, static_map=OccupancyGrid(SPEC, data))
    assert list(layered.grids) == ["static", "lidar", "social", "inflation"]
    off_map = simulate_scan((20.0, 0.0, 0.0), [], beams=8)
    with pytest.raises(ValueError, match="outside the costmap"):  # after the static layer reported its map
        layered.update(LayerInputs(scan=off_map))
    assert (layered.master.costs == NO_INFORMATION).all()
    assert layered.update(LayerInputs()) == SPEC.whole  # no scan, nobody: the map alone, still to be written
    master = layered.master.costs
    assert (master[100, 10:] == LETHAL).all() and (master[:90, :10] == NO_INFORMATION).all()
    assert (master[:85, 10:] == FREE_SPACE).all() and master[95, 50] == INSCRIBED
    window = layered.update(LayerInputs([Person(1, 4.0, -2.0, 0.0)]))
    assert window is not None and window != SPEC.whole
    assert (layered.master.costs[100, 10:] == LETHAL).all()
    assert layered.layer("static").update(LayerInputs(), None) is None


def test_the_plugin_list_names_orders_and_checks_the_layers():
    layered = layered_costmap(SPEC)
    assert [layer.name for layer in layered.layers] == ["lidar", "social", "inflation"]  # no static map, no static
    assert isinstance(layered.layer("lidar"), ObstacleLayer) and layered.layer("static") is None
    assert layered.layer("lidar").people_clear_radius == pytest.approx(0.2 + 0.1)
    baseline = layered_costmap(SPEC, CostmapParams().without("social"), body_radius=0.3)
    assert baseline.layer("lidar").people_clear_radius == 0.0  # nobody draws the people: their marks stay
    assert layered_costmap(SPEC, CostmapParams(), body_radius=0.3).layer("lidar").people_clear_radius == 0.4
    renamed = layered_costmap(
        SPEC, CostmapParams(plugins=("lidar", "rear", "inflation")), plugins={**PLUGINS, "rear": PLUGINS["lidar"]}
    )
    assert list(renamed.grids) == ["lidar", "rear", "inflation"]
    with pytest.raises(ValueError, match="unknown layer 'sonar'"):
        layered_costmap(SPEC, CostmapParams(plugins=("lidar", "sonar")))
    with pytest.raises(ValueError, match="listed twice"):
        CostmapParams(plugins=("lidar", "lidar"))
    with pytest.raises(ValueError, match="distinct names"):
        LayeredCostmap(SPEC, [ObstacleLayer(SPEC), ObstacleLayer(SPEC)])
    with pytest.raises(ValueError, match="differs from the costmap"):
        LayeredCostmap(SPEC, [InflationLayer(GridSpec(0.1, 0.0, 0.0, 10, 10), InflationParams(), 0.25)])
    with pytest.raises(ValueError, match="combination method"):
        Unknown(SPEC, "min")


def test_the_lidar_layer_clears_people_marks_by_its_own_parameter():
    people = [Person(1, 4.0, 0.0, np.pi)]
    scan = simulate_scan((0.0, 0.0, 0.0), WALLS, people, beams=720)
    near = SPEC.window((3.5, -0.5), (4.5, 0.5))
    for radius, marks in ((0.0, True), (0.3, False)):
        layer = ObstacleLayer(SPEC, people_clear_radius=radius)
        window = layer.update(LayerInputs(people, (), scan), None)
        assert ((layer.costs[near.slices] == LETHAL).any()) == marks
        assert (layer.costs == LETHAL).any() and window is not None
        assert layer.update(LayerInputs(people), None) is None  # no scan and nothing left to clear: no change
        mark = SPEC.window((4.1, 0.05), (4.1, 0.05))
        assert mark is not None
        layer.costs[mark.slices] = LETHAL  # within 0.3 m of the person: theirs when the layer clears people's marks
        assert layer.update(LayerInputs(people), None) == (None if radius == 0 else mark)  # the window of what changed
    with pytest.raises(ValueError, match="people_clear_radius"):
        ObstacleLayer(SPEC, people_clear_radius=-1.0)


def test_a_scenario_names_its_layers_in_order(tmp_path):
    from sid.scenario.build import build_costmap
    from sid.scenario.loader import ScenarioError, scenario_from_dict

    data = {
        "map": {"resolution": 0.05, "origin": [0.0, 0.0], "size": [4.0, 3.0]},
        "people": [{"id": 1, "x": 2.0, "y": 1.5}],
        "robot": {"start": [0.5, 1.5], "goal": [3.5, 1.5]},
        "layers": {"plugins": ["lidar", "inflation"]},
    }
    layered = build_costmap(scenario_from_dict(data, base_dir=tmp_path))
    assert list(layered.grids) == ["lidar", "inflation"]
    assert layered.master.cost_at([[2.0, 2.3]])[0] == FREE_SPACE  # no personal space: the person is a LiDAR mark
    for plugins, message in (
        (["lidar", "sonar"], r'layers\.plugins\[1\]: unknown layer "sonar"'),
        (["lidar", "lidar"], r"layers\.plugins: a layer is listed twice"),
        ("lidar", r"layers\.plugins: expected a list of layer names"),
        ([], r"layers\.plugins: \[\] has no layer that marks people; list one of lidar, social, tracked_people"),
        (["static", "inflation"], r"layers\.plugins: \['static', 'inflation'\] has no layer that marks people"),
    ):
        with pytest.raises(ScenarioError, match=message):
            scenario_from_dict({**data, "layers": {"plugins": plugins}}, base_dir=tmp_path)

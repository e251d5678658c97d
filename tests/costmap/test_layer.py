"""The layer interface: the windows a layer reports, a new layer as one class, its combination method in its place,
the inputs as typed keys and a new kind of input declared beside the layer that reads it."""

from __future__ import annotations

import itertools
from collections.abc import Iterable, Sequence

import numpy as np
import pytest

from costmap.grid import FREE_SPACE, INSCRIBED, LETHAL, GridSpec, Window, union
from costmap.layer import Input, Layer, LayerInputs
from costmap.layered import LayeredCostmap
from costmap.layers.obstacle import SCAN
from costmap.layers.social import GROUPS, PEOPLE
from costmap.plugins import PLUGINS, CostmapParams, layered_costmap
from sid.perception.people import Person
from tests.costmap.scenes import Unknown, frames

SPEC = GridSpec.from_size(0.05, (-1.0, -4.0), (10.0, 8.0))


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


def _doorways(points: Iterable[Sequence[float]]) -> tuple[tuple[float, float], ...]:
    doorways = tuple((float(x), float(y)) for x, y in points)
    if not np.isfinite(doorways).all():
        raise ValueError("a doorway needs a finite position")
    return doorways


DOORWAYS: Input[tuple[tuple[float, float], ...]] = Input("doorways", (), _doorways)
"""A kind of input the costmap core has never heard of: doorway points (world frame, m) to keep clear."""

KEEP_CLEAR = 200


class Doorways(Layer):
    """A 0.5 m square of KEEP_CLEAR cost centred on each doorway, repainted every frame."""

    name = "doorways"
    combination = "max"
    reads = (DOORWAYS,)

    def __init__(self, spec: GridSpec) -> None:
        super().__init__(spec)
        self._painted: Window | None = None

    def update(self, inputs: LayerInputs, changed: Window | None) -> Window | None:
        previous, self._painted = self._painted, None
        if previous is not None:
            self.costs[previous.slices] = FREE_SPACE
        for x, y in inputs.get(DOORWAYS):
            window = self.spec.window((x - 0.25, y - 0.25), (x + 0.25, y + 0.25))
            if window is not None:
                self.costs[window.slices] = KEEP_CLEAR
                self._painted = window.union(self._painted)
        return union(previous, self._painted)


def test_layer_inputs_map_typed_keys_to_checked_values_and_read_defaults_for_the_rest():
    person = Person(1, 2.0, 0.0, 0.0)
    inputs = LayerInputs({PEOPLE: [person], DOORWAYS: [[1, 2]]})
    assert inputs[PEOPLE] == (person,) and inputs[DOORWAYS] == ((1.0, 2.0),)  # each value through its key's check
    assert inputs.get(GROUPS) == () and inputs.get(SCAN) is None and inputs.get(SCAN, "none") == "none"
    assert list(inputs) == [PEOPLE, DOORWAYS] and GROUPS not in inputs and len(inputs) == 2
    with pytest.raises(KeyError):
        _ = inputs[GROUPS]
    assert LayerInputs({**inputs, GROUPS: []}) == LayerInputs({PEOPLE: (person,), DOORWAYS: [(1, 2)], GROUPS: ()})
    assert LayerInputs() == {} and repr(LayerInputs({GROUPS: []})) == "LayerInputs({groups: ()})"
    with pytest.raises(TypeError):
        inputs[GROUPS] = ()  # type: ignore[index]
    with pytest.raises(AttributeError):
        inputs.people = ()  # type: ignore[attr-defined]
    with pytest.raises(ValueError, match="finite"):
        LayerInputs({DOORWAYS: [(np.nan, 0.0)]})
    with pytest.raises(ValueError, match="two different inputs are named 'people'"):
        LayerInputs({PEOPLE: [], Input("people", ()): []})
    with pytest.raises(TypeError, match="keyed by Input, got str"):
        LayerInputs({"people": []})  # type: ignore[dict-item]


def test_a_new_kind_of_input_is_one_key_beside_the_layer_that_reads_it():
    plugins = {**PLUGINS, "doorways": lambda c: Doorways(c.spec)}
    layered = layered_costmap(
        SPEC, CostmapParams(plugins=("lidar", "doorways", "social", "inflation")), plugins=plugins
    )
    plain = layered_costmap(SPEC, CostmapParams(plugins=("lidar", "social", "inflation")))
    assert layered.reads == (SCAN, PEOPLE, DOORWAYS, GROUPS) and plain.reads == (SCAN, PEOPLE, GROUPS)
    first, second = frames()[:2]
    with_doorway = LayerInputs({**first, DOORWAYS: [(1.0, -3.0)]})  # the standard inputs and the new one
    layered.update(with_doorway)
    plain.update(with_doorway)  # a costmap none of whose layers reads doorways takes them and paints nothing for them
    door = SPEC.window((0.75, -3.25), (1.25, -2.75))
    assert door is not None
    expected = plain.master.costs.copy()
    expected[door.slices] = np.maximum(expected[door.slices], KEEP_CLEAR)
    assert (plain.master.costs[door.slices] < KEEP_CLEAR).any()  # the doorway shows
    np.testing.assert_array_equal(layered.master.costs, expected)  # and nothing else differs
    layered.update(second)  # a frame without doorways: nothing to paint for them
    plain.update(second)
    np.testing.assert_array_equal(layered.master.costs, plain.master.costs)
    assert not layered.grids["doorways"].any()


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
    inputs = LayerInputs({PEOPLE: [Person(1, 2.0, 2.0, 0.0)]})  # no scan: only the person's body and personal space
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

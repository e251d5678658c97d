"""The master grid and its ordered layers (Nav2's LayeredCostmap); which layers, and in what order, is configuration
(``costmap.plugins``)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from costmap.grid import FREE_SPACE, Costmap2D, GridSpec, Window, disjoint, union
from costmap.layer import Input, Layer, LayerInputs
from sid.errors import InputError

__all__ = ["LayeredCostmap"]


class LayeredCostmap:
    """A master grid and an ordered list of layers over the same grid.

    ``update`` hands every layer, in order, the frame's inputs and collects the windows they changed
    (``Layer.update_windows``), merged where they overlap or lie close (``disjoint``); the master is then reset to
    ``default_value`` (FREE, or NO_INFORMATION when unknown space is tracked) over those windows (``windows``) and
    every layer, in order, writes its costs there. Windows of an update that raised are written at the next one.
    ``reads``: the inputs its layers read; a frame without one of them reads as its default (nothing to paint).
    """

    def __init__(self, spec: GridSpec, layers: Sequence[Layer], default_value: int = FREE_SPACE) -> None:
        names = [layer.name for layer in layers]
        if len(set(names)) != len(names):
            raise InputError(f"costmap layers need distinct names, got {names}")
        for layer in layers:
            if layer.spec != spec:
                raise InputError(f"layer {layer.name!r}: its grid {layer.spec} differs from the costmap's {spec}")
        self.spec = spec
        self.layers = list(layers)
        self.default_value = int(default_value)
        self.master = Costmap2D.filled(spec, self.default_value)
        self.inputs = LayerInputs()  # the inputs last applied
        self.windows: list[Window] = []  # the disjoint windows the last update wrote
        self._pending: list[Window] = []  # changed but not yet written into the master

    def layer(self, name: str) -> Layer | None:
        """The layer called ``name``, or None."""
        return next((layer for layer in self.layers if layer.name == name), None)

    @property
    def reads(self) -> tuple[Input[Any], ...]:
        """The inputs its layers read, each once, in layer order (Nav2: the sources its plugins subscribe to)."""
        return tuple(dict.fromkeys(key for layer in self.layers for key in layer.reads))

    @property
    def grids(self) -> dict[str, np.ndarray]:
        """Each layer's own uint8 grid by name, in combination order."""
        return {layer.name: layer.costs for layer in self.layers}

    def update(self, inputs: LayerInputs) -> Window | None:
        """Bring every layer to ``inputs``, then recombine the master where anything changed (``windows``); returns
        the smallest window holding those (Nav2's update bounds), None when nothing changed. An input the layers do
        not read is kept (``inputs``) but read by none; one named as an input they read but another key is refused
        (ValueError, nothing changed): the layers would not see it."""
        read = {key.name: key for key in self.reads}
        strangers = [key.name for key in inputs if read.get(key.name, key) is not key]
        if strangers:
            raise InputError(f"inputs {strangers}: not the keys of these names that the layers read")
        for layer in self.layers:
            changed = layer.update_windows(inputs, self._pending)
            self._pending = disjoint([*self._pending, *changed])
        self.inputs = inputs
        self.windows, self._pending = self._pending, []
        master = self.master.costs
        for window in self.windows:
            master[window.slices] = self.default_value
        for layer in self.layers:  # each layer over every window before the next: inflation reads the lethal cells
            for window in self.windows:  # within reach of its window, which may lie in another
                layer.write(master, window)
        return union(*self.windows)

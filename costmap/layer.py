"""The costmap layer interface, in the spirit of Nav2's costmap_2d plugins.

Every frame, ``LayeredCostmap.update`` hands each layer, in order, the same ``LayerInputs``; the layer updates its own
uint8 grid and reports the window of cells it changed (Nav2's ``updateBounds``), or several (``update_windows``: a
layer whose changes lie far apart, as people in distant groups, spares the costmap the cells between them). The
master grid is then reset over those windows (``costmap.grid.disjoint``) and every layer, in order, writes its grid
there with its combination method (Nav2's ``updateCosts``; methods in ``costmap.combine``). A layer may read the
master in ``write`` (inflation does).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from costmap.combine import CombinationMethod, check_method, combine
from costmap.grid import FREE_SPACE, GridSpec, Window, union
from costmap.scan import LaserScan
from sid.checks import check_numbers
from sid.perception.group import Group
from sid.perception.people import Person
from sid.tracking.records import Tracks

__all__ = ["Layer", "LayerInputs", "RepaintedLayer"]


@dataclass(frozen=True)
class LayerInputs:
    """What the layers see in one frame: people and their groups (world frame), when there is one a 2D scan, and
    when a tracker runs its tracked people and groups (``tracks``, same frame; read by the tracked-people layer).

    People need finite poses and distinct ids. New kinds of input (tracked people, a robot pose, ...) are new fields
    with a default, so existing layers and callers are unaffected.
    """

    people: Sequence[Person] = ()
    groups: Sequence[Group] = ()
    scan: LaserScan | None = None
    tracks: Tracks | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "people", tuple(self.people))
        object.__setattr__(self, "groups", tuple(self.groups))
        seen = set()
        for p in self.people:
            check_numbers(f"person {p.id}", p, ("x", "y") if p.theta is None else ("x", "y", "theta"))
            if p.id in seen:
                raise ValueError(f"person id {p.id} appears twice")
            seen.add(p.id)


class Layer(ABC):
    """One layer: its own uint8 grid ``costs`` over ``spec`` (Nav2 cost values), written into the master grid with
    ``combination``. Subclasses set ``name`` (unique within a costmap) and ``combination``, and implement ``update``.
    """

    name: str
    combination: CombinationMethod

    def __init__(self, spec: GridSpec, fill: int = FREE_SPACE) -> None:
        check_method(self.combination)
        self.spec = spec
        self.costs = np.full(spec.shape, fill, dtype=np.uint8)

    @abstractmethod
    def update(self, inputs: LayerInputs, changed: Window | None) -> Window | None:
        """Bring the layer to this frame's ``inputs``; return the window of cells it changed (None: none).

        ``changed``: the union of the windows the layers before this one changed (and any not yet written).
        Raise ValueError before changing anything when the inputs cannot be used.
        """

    def update_windows(self, inputs: LayerInputs, changed: Sequence[Window]) -> list[Window]:
        """``update``, with the changed cells reported as windows (they may overlap; none: nothing changed) and the
        windows the layers before this one changed given as such. By default ``update``'s one window; a layer
        whose changes can lie far apart overrides it (``update`` then returns the union of these windows)."""
        window = self.update(inputs, union(*changed))
        return [] if window is None else [window]

    def write(self, master: np.ndarray, window: Window) -> None:
        """Combine this layer's costs into ``master`` (the combined grid) over ``window``."""
        rows, cols = window.slices
        combine(master[rows, cols], self.costs[rows, cols], self.combination)


class RepaintedLayer(Layer):
    """A layer rebuilt at every update in windows that may lie far apart (people and their zones):
    ``update_windows`` does the work, ``update`` returns the union of its windows."""

    def update(self, inputs: LayerInputs, changed: Window | None) -> Window | None:
        """``update_windows``' windows as one (None: nothing changed)."""
        return union(*self.update_windows(inputs, [] if changed is None else [changed]))

    @abstractmethod
    def update_windows(self, inputs: LayerInputs, changed: Sequence[Window]) -> list[Window]:
        """Repaint the layer for ``inputs``; the windows of the last update's paint (now cleared) and of this one's."""

"""The costmap layer interface, in the spirit of Nav2's costmap_2d plugins.

Every frame, ``LayeredCostmap.update`` hands each layer, in order, the same ``LayerInputs``; the layer updates its own
uint8 grid and reports the window of cells it changed (Nav2's ``updateBounds``), or several (``update_windows``: a
layer whose changes lie far apart, as people in distant groups, spares the costmap the cells between them). The
master grid is then reset over those windows (``costmap.grid.disjoint``) and every layer, in order, writes its grid
there with its combination method (Nav2's ``updateCosts``; methods in ``costmap.combine``). A layer may read the
master in ``write`` (inflation does).

As a Nav2 plugin subscribes to its own sources, each layer declares the kinds of input it reads (``Layer.reads``,
``Input`` keys), and each key is declared beside a layer that reads it (``costmap.layers``, or a plugin of one's
own): this module and ``costmap.layered`` know no kind of input, so a new one edits neither.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Generic, TypeVar, overload

import numpy as np

from costmap.combine import CombinationMethod, check_method, combine
from costmap.grid import FREE_SPACE, GridSpec, Window, union
from sid.errors import InputError, InputTypeError

__all__ = ["Input", "Layer", "LayerInputs", "RepaintedLayer"]

_T = TypeVar("_T")  # what an input carries
_D = TypeVar("_D")  # a default given to ``LayerInputs.get``


@dataclass(frozen=True, eq=False)  # a key is itself: compared and hashed by identity, as a ContextVar
class Input(Generic[_T]):
    """One kind of layer input, the key of its value in ``LayerInputs``; its type parameter is what it carries.

    ``name``: what messages call it (distinct among the keys of one ``LayerInputs``). ``default``: its value in a
    frame that does not give it (what means nothing to paint). ``check``: makes a given value the one the layers read
    (e.g. a tuple of a sequence), raising ValueError when it cannot be used; None: the value as given.
    """

    name: str
    default: _T
    check: Callable[[Any], _T] | None = None

    def __repr__(self) -> str:
        return f"Input({self.name!r})"


class LayerInputs(Mapping[Input[Any], Any]):
    """What the layers see in one frame: a value for each kind of input given (immutable; each value passed through
    its key's ``check`` here). ``inputs[KEY]`` is the value given (KeyError when none is), ``inputs.get(KEY)`` the
    value or the key's default."""

    __slots__ = ("_values",)

    def __init__(self, values: Mapping[Input[Any], Any] | None = None) -> None:
        checked: dict[Input[Any], Any] = {}
        names: dict[str, Input[Any]] = {}
        for key, value in (values or {}).items():
            if not isinstance(key, Input):
                raise InputTypeError(f"layer inputs are keyed by Input, got {type(key).__name__}")
            if names.setdefault(key.name, key) is not key:
                raise InputError(f"two different inputs are named {key.name!r}")
            checked[key] = value if key.check is None else key.check(value)
        self._values = checked

    def __getitem__(self, key: Input[_T]) -> _T:
        value: _T = self._values[key]
        return value

    @overload
    def get(self, key: Input[_T], /) -> _T: ...
    @overload
    def get(self, key: Input[_T], default: _D, /) -> _T | _D: ...
    def get(self, key: Input[Any], *default: Any) -> Any:
        """The value given for ``key``, else ``default`` when given, else the key's own default."""
        if key in self._values:
            return self._values[key]
        return default[0] if default else key.default

    def __iter__(self) -> Iterator[Input[Any]]:
        return iter(self._values)

    def __len__(self) -> int:
        return len(self._values)

    def __repr__(self) -> str:
        return "LayerInputs({" + ", ".join(f"{key.name}: {value!r}" for key, value in self._values.items()) + "})"


class Layer(ABC):
    """One layer: its own uint8 grid ``costs`` over ``spec`` (Nav2 cost values), written into the master grid with
    ``combination``. Subclasses set ``name`` (unique within a costmap), ``combination`` and ``reads`` (the inputs
    ``update`` reads; none by default), and implement ``update``.
    """

    name: str
    combination: CombinationMethod
    reads: tuple[Input[Any], ...] = ()

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

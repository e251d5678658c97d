"""How a layer's grid is written into the combined (master) grid: Nav2's combination methods and two of ours, in place.

- max: keep the larger value; an unknown (255) layer cell is ignored, an unknown master cell is overwritten.
- max_nonzero: max, and a free (0) layer cell is ignored as an unknown one is: it carries no opinion, so unknown
  space stays unknown (the social layer).
- max_keep_unknown: max, but an unknown master cell stays unknown unless the layer value is >= 253 (Nav2's inflation
  rule).
- overwrite: copy the layer value unless it is unknown.
- true_overwrite: copy every value, unknown included.
- addition: sum, capped at 252 (MAX_NON_OBSTACLE); unknown layer cells are ignored and an unknown master cell
  takes the layer value.

Every function also works on views (a window of the grids).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Literal

import cv2
import numpy as np

from costmap.grid import FREE_SPACE, INSCRIBED, NO_INFORMATION
from sid.errors import InputError

__all__ = [
    "COMBINE",
    "CombinationMethod",
    "check_method",
    "combine",
    "update_with_addition",
    "update_with_max",
    "update_with_max_keep_unknown",
    "update_with_max_nonzero",
    "update_with_overwrite",
    "update_with_true_overwrite",
]

CombinationMethod = Literal["max", "max_nonzero", "max_keep_unknown", "overwrite", "true_overwrite", "addition"]


def _holds_unknown(grid: np.ndarray) -> bool:
    """Whether a cell of ``grid`` (uint8) is unknown: its largest value (one reduction, cheaper than a mask)."""
    return int(grid.max(initial=0)) == NO_INFORMATION


def _opencv_max(master: np.ndarray, layer: np.ndarray) -> bool:
    """master = max(master, layer) in place with OpenCV (one pass, faster than numpy's: docs/benchmarks.md,
    "Costmap") when it takes both grids as they lie in memory (1-D or 2-D, not empty, each row's cells adjacent);
    returns whether it did."""
    if not all(g.ndim <= 2 and g.size > 0 and g.strides[-1] == 1 and min(g.strides) > 0 for g in (master, layer)):
        return False
    cv2.max(master, layer, dst=master)
    return True


def update_with_max(master: np.ndarray, layer: np.ndarray, ignore_free: bool = False) -> None:
    """Nav2's max: unknown layer cells leave the master untouched, and free ones too with ``ignore_free``."""
    # With no unknown master or layer cell it is the plain max (a free layer cell never raises it): the usual case,
    # without masks.
    if not _holds_unknown(layer) and not _holds_unknown(master) and _opencv_max(master, layer):
        return
    master_unknown = master == NO_INFORMATION
    larger = np.maximum(master, layer)
    np.copyto(larger, layer, where=master_unknown)
    opinion = layer != NO_INFORMATION
    if ignore_free:
        opinion &= layer != FREE_SPACE
    np.copyto(master, larger, where=opinion)


def update_with_max_nonzero(master: np.ndarray, layer: np.ndarray) -> None:
    update_with_max(master, layer, ignore_free=True)


def update_with_max_keep_unknown(master: np.ndarray, layer: np.ndarray) -> None:
    replace = (master == NO_INFORMATION) & (layer >= INSCRIBED) if _holds_unknown(master) else None
    if not _opencv_max(master, layer):  # an unknown master cell stays 255 here
        np.maximum(master, layer, out=master)
    if replace is not None:
        np.copyto(master, layer, where=replace)


def update_with_overwrite(master: np.ndarray, layer: np.ndarray) -> None:
    known = layer != NO_INFORMATION
    master[known] = layer[known]


def update_with_true_overwrite(master: np.ndarray, layer: np.ndarray) -> None:
    master[...] = layer


def update_with_addition(master: np.ndarray, layer: np.ndarray) -> None:
    known = layer != NO_INFORMATION
    master_unknown = known & (master == NO_INFORMATION)
    summed = np.minimum(master.astype(np.int16) + layer, INSCRIBED - 1).astype(np.uint8)
    add = known & ~master_unknown
    master[add] = summed[add]
    master[master_unknown] = layer[master_unknown]


COMBINE: dict[str, Callable[[np.ndarray, np.ndarray], None]] = {
    "max": update_with_max,
    "max_nonzero": update_with_max_nonzero,
    "max_keep_unknown": update_with_max_keep_unknown,
    "overwrite": update_with_overwrite,
    "true_overwrite": update_with_true_overwrite,
    "addition": update_with_addition,
}


def check_method(method: str) -> None:
    """Raise ValueError unless ``method`` is one of the combination methods above."""
    if method not in COMBINE:
        raise InputError(f"unknown combination method {method!r}; use one of {sorted(COMBINE)}")


def combine(master: np.ndarray, layer: np.ndarray, method: CombinationMethod = "max") -> None:
    """Write ``layer`` into ``master`` (same shape, uint8) with one of the combination methods above."""
    if master.shape != layer.shape:
        raise InputError(f"combine: layer shape {layer.shape} differs from the master's {master.shape}")
    check_method(method)
    COMBINE[method](master, layer)

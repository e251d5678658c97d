"""Label placement on images: where blocks of text go so that they cover neither each other nor what is drawn.

Image coordinates: u right, v down, pixels. Used by the camera overlay (``sid.perception.overlay``) and the top-view
and costmap pictures (``costmap.render``).
"""

from __future__ import annotations

from collections.abc import Sequence

import cv2
import numpy as np

from sid.errors import InputError

__all__ = ["place_labels"]


def place_labels(
    sizes: Sequence[tuple[int, int]],
    boxes: Sequence[np.ndarray | Sequence[float]],
    shape: tuple[int, int],
    gap: int = 1,
    avoid: np.ndarray | None = None,
    prefer: Sequence[tuple[int, int]] | None = None,
) -> list[tuple[int, int]]:
    """Top-left corners (u, v) of label blocks of ``sizes`` (w, h) px, one per box (u0, v0, u1, v1), in an image of
    ``shape`` (h, w).

    Each block goes, in the order given, to the free spot nearest (in u + v distance) to its preferred place (its
    corner in ``prefer``; by default just above its box's top-left corner): inside the image, centred over its box's
    columns or between them and the preferred place, at least ``gap`` px from the blocks already placed and covering
    none of the ``avoid`` pixels (a boolean (h, w) mask of what is drawn already: arrows, markers, paths). When no
    spot is free, it goes where it covers the least of both.
    """
    height, width = shape
    if avoid is not None and avoid.shape != (height, width):
        raise InputError(f"place_labels: avoid mask of shape {avoid.shape} for an image of {(height, width)}")
    drawn = None if avoid is None else cv2.integral(avoid.astype(np.uint8))  # (h + 1, w + 1) running sums
    placed: list[tuple[int, int, int, int]] = []
    corners = []
    for i, ((w, h), box) in enumerate(zip(sizes, boxes, strict=True)):
        u0, v0, u1 = (int(round(float(c))) for c in box[:3])
        hi_u, hi_v = max(0, width - w), max(0, height - h)
        want = (u0, v0 - 2 - h) if prefer is None else prefer[i]
        want_u, want_v = int(np.clip(want[0], 0, hi_u)), int(np.clip(want[1], 0, hi_v))
        first, last = np.clip([min(u0 - w // 2, want_u), max(u1 - w // 2, want_u)], 0, hi_u)
        us = np.union1d(np.arange(first, last + 1), [want_u])
        u, v = (grid.ravel() for grid in np.meshgrid(us, np.arange(hi_v + 1)))
        overlap = np.zeros(u.shape)
        for a0, b0, a1, b1 in placed:
            du = np.minimum(u + w, a1 + gap) - np.maximum(u, a0 - gap)
            dv = np.minimum(v + h, b1 + gap) - np.maximum(v, b0 - gap)
            overlap += np.clip(du, 0, None) * np.clip(dv, 0, None)
        if drawn is not None:
            u_end, v_end = np.minimum(u + w, width), np.minimum(v + h, height)
            overlap += drawn[v_end, u_end] - drawn[v, u_end] - drawn[v_end, u] + drawn[v, u]
        best = int(np.lexsort((np.abs(u - want_u) + np.abs(v - want_v), overlap))[0])
        corners.append((int(u[best]), int(v[best])))
        placed.append((corners[-1][0], corners[-1][1], corners[-1][0] + w, corners[-1][1] + h))
    return corners

"""Trajectory sets written for tests (obsmat.txt + groups.txt, ETH/UCY format; ground frame, metres, 0.4 s steps)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path


def write_set(folder: Path, rows: Sequence[Sequence[float]], groups: str = "") -> Path:
    """``folder`` holding ``rows`` (frame, id, x, z, y, vx, vz, vy) and ``groups`` as given."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "obsmat.txt").write_text("\n".join(" ".join(f"{v:.6e}" for v in row) for row in rows) + "\n")
    (folder / "groups.txt").write_text(groups)
    return folder


def pair_and_strangers(folder: Path, frames: int = 40) -> Path:
    """Pedestrians 1 and 2 walk side by side (0.6 m apart, +x, 1.2 m/s, grouped), 3 and 4 alone the other way 4 and
    7 m to their left."""
    rows: list[tuple[float, ...]] = []
    for k in range(frames):
        x = 0.48 * k
        rows += [(k, 1, x, 0, 0.0, 1.2, 0, 0), (k, 2, x, 0, 0.6, 1.2, 0, 0)]
        rows += [(k, 3, 19 - x, 0, 4.0, -1.2, 0, 0), (k, 4, 19 - x, 0, 7.0, -1.2, 0, 0)]
    return write_set(folder, rows, "1 2\n")

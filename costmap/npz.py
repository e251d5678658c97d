"""Exact costmap archives (.npz): the combined uint8 grid, each layer's grid, resolution and origin."""

from __future__ import annotations

import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from costmap.grid import Costmap2D, GridSpec
from costmap.layered import LayeredCostmap
from sid.errors import InputError

__all__ = ["SavedCostmap", "load_npz", "save_npz"]


@dataclass
class SavedCostmap:
    """What a .npz archive holds: the combined costmap and each layer's grid by name (rows, cols), row 0 = lowest y."""

    master: Costmap2D
    layers: dict[str, np.ndarray]

    @property
    def spec(self) -> GridSpec:
        return self.master.spec


def save_npz(path: str | Path, layered: LayeredCostmap) -> Path:
    """Write ``costmap`` (combined), ``layer_<name>`` grids, ``layer_names``, ``resolution`` and ``origin`` [x, y]."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    spec = layered.spec
    layers = layered.grids
    np.savez_compressed(
        path,
        costmap=layered.master.costs,
        layer_names=np.array(list(layers)),
        resolution=np.float64(spec.resolution),
        origin=np.array([spec.origin_x, spec.origin_y]),
        allow_pickle=True,  # numpy's default, spelled out so type checkers do not bind the layer grids below to it
        **{f"layer_{name}": grid for name, grid in layers.items()},
    )
    return path


def load_npz(path: str | Path) -> SavedCostmap:
    """Read an archive written by ``save_npz``; a missing key, a wrong shape or dtype (grids are uint8) or a bad
    geometry names the file and the key."""
    path = Path(path)
    try:
        archive = np.load(path, allow_pickle=False)
    except (OSError, ValueError, zipfile.BadZipFile) as exc:
        raise InputError(f"{path}: cannot read costmap archive ({exc})") from exc
    with archive:
        missing = [k for k in ("costmap", "layer_names", "resolution", "origin") if k not in archive]
        if missing:
            raise InputError(f"{path}: not a costmap archive, missing '{missing[0]}'")
        costs = archive["costmap"]
        origin = archive["origin"]
        if costs.ndim != 2 or origin.shape != (2,):
            raise InputError(f"{path}: 'costmap' must be 2-D and 'origin' [x, y]")
        rows, cols = costs.shape
        try:
            spec = GridSpec(float(archive["resolution"]), float(origin[0]), float(origin[1]), cols, rows)
            master = Costmap2D(spec, costs)
        except (TypeError, ValueError) as exc:
            raise InputError(f"{path}: {exc}") from exc
        layers = {}
        for name in archive["layer_names"].tolist():
            key = f"layer_{name}"
            grid = archive.get(key)
            if grid is None or grid.shape != spec.shape or grid.dtype != np.uint8:
                found = "missing" if grid is None else f"{grid.dtype} {grid.shape}"
                raise InputError(f"{path}: layer '{name}' must be uint8 of shape {spec.shape}, got {found}")
            layers[name] = grid
    return SavedCostmap(master, layers)

"""Everything ``sid costmap`` writes for one costmap: map_server files, .npz, .mcap and a picture; and the
``nav_msgs/OccupancyGrid`` filter mask that Nav2's KeepoutFilter reads back as the same costs (``sid ros``).

Nav2's costmap filters turn a mask value v in 0..100 into the cost round(v * 254 / 100) (-1: no information, the
cell is left alone) and raise a master cell to it when higher. ``keepout_mask`` picks, per cost c, the value
v = round(c * 100 / 254), so a cost comes back within 1.27 of itself (240, a group zone, comes back as 239; 254
as 254). This differs from the costmap publisher's table (``costmap.occupancy``), which the filters would read
back as up to 7 % less.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from pathlib import Path

import cv2
import numpy as np

from costmap.grid import LETHAL, NO_INFORMATION, Costmap2D
from costmap.layered import LayeredCostmap
from costmap.mapfile import write_map
from costmap.npz import save_npz
from costmap.occupancy import OCC_OCCUPIED, OCC_UNKNOWN, OccupancyGrid, cost_to_occupancy, costmap_to_occupancy
from costmap.render import Outline, RobotTask, render_costmap
from costmap.rosbag import write_occupancy_mcap
from sid.errors import InputError

__all__ = ["NAMES", "export_costmap", "filter_mask_cost", "keepout_mask"]

NAMES = ("costmap.yaml", "costmap.pgm", "costmap.npz", "costmap.mcap", "costmap.png")


def export_costmap(
    layered: LayeredCostmap,
    out_dir: str | Path,
    *,
    robot: RobotTask | None = None,
    title: str | None = None,
    stamp_ns: int | None = None,
    outlines: Sequence[Outline] = (),
) -> dict[str, Path]:
    """Write DIR/costmap.{yaml,pgm,npz,mcap,png}; existing files of those names are replaced.

    The MCAP holds /costmap (combined) and, with a social layer, /social_costmap; ``stamp_ns`` defaults to now.
    ``outlines``: shapes of the known map the picture draws whole (``costmap.render.render_costmap``).
    """
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise InputError(f"{out}: exists and is not a directory")
    out.mkdir(parents=True, exist_ok=True)
    for name in NAMES:
        (out / name).unlink(missing_ok=True)
    paths = {"yaml": out / "costmap.yaml"}
    paths["pgm"] = write_map(paths["yaml"], costmap_to_occupancy(layered.master))
    paths["npz"] = save_npz(out / "costmap.npz", layered)
    topics = {"/costmap": costmap_to_occupancy(layered.master)}
    social = layered.layer("social")
    if social is not None:
        topics["/social_costmap"] = OccupancyGrid(layered.spec, cost_to_occupancy(social.costs))
    stamp = time.time_ns() if stamp_ns is None else stamp_ns
    paths["mcap"] = write_occupancy_mcap(out / "costmap.mcap", topics, stamp_ns=stamp)
    paths["png"] = out / "costmap.png"
    if not cv2.imwrite(str(paths["png"]), render_costmap(layered, robot=robot, title=title, outlines=outlines)):
        raise OSError(f"{paths['png']}: cannot write the picture")
    return paths


def keepout_mask(costmap: Costmap2D, frame_id: str = "map") -> OccupancyGrid:
    """A costmap as a KeepoutFilter mask: cost c -> round(c * 100 / 254), 255 (unknown) -> -1 (see the docstring)."""
    costs = costmap.costs.astype(np.float64)
    data = np.rint(costs * OCC_OCCUPIED / LETHAL).astype(np.int8)
    data[costmap.costs == NO_INFORMATION] = OCC_UNKNOWN
    return OccupancyGrid(costmap.spec, data, frame_id=frame_id)


def filter_mask_cost(data: np.ndarray) -> np.ndarray:
    """The uint8 costs Nav2's costmap filters read from mask values: v in 0..100 -> round(v * 254 / 100),
    -1 -> 255 (no information: the filter leaves that cell alone)."""
    values = np.asarray(data)
    if values.dtype != np.int8 or np.any((values < OCC_UNKNOWN) | (values > OCC_OCCUPIED)):
        raise InputError("filter mask: values must be int8 in -1..100")
    costs = np.floor(values.astype(np.float64) * LETHAL / OCC_OCCUPIED + 0.5).astype(np.int16)
    return np.where(values == OCC_UNKNOWN, NO_INFORMATION, costs).astype(np.uint8)

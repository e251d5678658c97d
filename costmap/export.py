"""Everything ``sid costmap`` writes for one costmap: map_server files, .npz, .mcap and a picture."""

from __future__ import annotations

import time
from collections.abc import Sequence
from pathlib import Path

import cv2

from costmap.layered import LayeredCostmap
from costmap.mapfile import write_map
from costmap.npz import save_npz
from costmap.occupancy import OccupancyGrid, cost_to_occupancy, costmap_to_occupancy
from costmap.render import Outline, RobotTask, render_costmap
from costmap.rosbag import write_occupancy_mcap

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
        raise ValueError(f"{out}: exists and is not a directory")
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

"""ROS map files (map_server / map_saver): a YAML description plus an image, read and written.

Reading follows nav2_map_server's ``loadMapFromFile``: the pixel's shade s in [0, 1] is the mean of its colour
channels (in trinary mode an alpha channel joins the mean); occupancy p = s if negate else 1 - s; then
- trinary: p > occupied_thresh -> 100, p < free_thresh -> 0, else -1;
- scale: a transparent pixel -> -1, p > occupied_thresh -> 100, p < free_thresh -> 0,
  else rint(100 * (p - free_thresh) / (occupied_thresh - free_thresh));
- raw: v = round(255 s) as is when 0 <= v <= 100, else -1 (negate does not apply, as in Nav2).
The image's top row is the map's highest y; rows are flipped so row 0 is the lowest y.

Writing uses mode ``raw`` with an 8-bit PGM whose pixels are the OccupancyGrid values (255 for unknown), so
map_server loads exactly the values written. (map_saver's trinary output would keep only three values.)
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import yaml

from costmap.grid import MAX_ORIGIN, GridSpec
from costmap.occupancy import OCC_OCCUPIED, OCC_UNKNOWN, OccupancyGrid
from sid.checks import check_limit
from sid.documents import ImageHeader, is_number, load_document, read_image_header, special_file, summary
from sid.errors import SidError

__all__ = ["MODES", "MapFileError", "read_map", "write_map"]

MODES = ("trinary", "scale", "raw")


class MapFileError(SidError, ValueError):
    """A map YAML or its image cannot be used; the message names the file and the problem."""


def _number(doc: dict, key: str, path: Path) -> float:
    if key not in doc:
        raise MapFileError(f"{path}: missing key '{key}'")
    value = doc[key]
    if not is_number(value):
        raise MapFileError(f"{path}: '{key}' must be a finite number, got {summary(value)}")
    return float(value)


def _read_metadata(path: Path) -> dict[str, Any]:
    try:
        doc = load_document(path, "map YAML")
    except ValueError as exc:  # names the file: unreadable, or not valid YAML
        raise MapFileError(str(exc)) from exc
    if not isinstance(doc, dict):
        raise MapFileError(f"{path}: expected a mapping of map_server keys, got {type(doc).__name__}")
    image = doc.get("image")
    if not isinstance(image, str) or not image:
        raise MapFileError(f"{path}: 'image' must name the map image")
    resolution = _number(doc, "resolution", path)
    if resolution <= 0:
        raise MapFileError(f"{path}: 'resolution' must be positive, got {resolution}")
    origin = doc.get("origin")
    if not isinstance(origin, list) or len(origin) != 3:
        raise MapFileError(f"{path}: 'origin' must be [x, y, yaw], got {summary(origin)}")
    origin = [_number({"origin": v}, "origin", path) for v in origin]
    if max(abs(origin[0]), abs(origin[1])) > MAX_ORIGIN:  # before the image is decoded (GridSpec checks it too)
        raise MapFileError(f"{path}: 'origin' x and y must lie within {MAX_ORIGIN:g} m, got {summary(origin)}")
    mode = doc.get("mode", "trinary")
    if mode not in MODES:
        raise MapFileError(f"{path}: 'mode' must be one of {MODES}, got {summary(mode)}")
    occupied, free = _number(doc, "occupied_thresh", path), _number(doc, "free_thresh", path)
    if mode != "raw" and not 0 <= free < occupied <= 1:
        raise MapFileError(f"{path}: need 0 <= free_thresh < occupied_thresh <= 1, got {free}, {occupied}")
    negate = doc.get("negate")
    if negate not in (0, 1, True, False):
        raise MapFileError(f"{path}: 'negate' must be 0 or 1, got {summary(negate)}")
    image_path = Path(image) if Path(image).is_absolute() else path.parent / image
    return dict(
        image=image_path,
        resolution=resolution,
        origin=origin,
        mode=mode,
        occupied=occupied,
        free=free,
        negate=bool(negate),
    )


def _netpbm_maxval(image: Path, header: ImageHeader) -> int | None:
    """The maximum value declared in a PGM/PPM header (the value of white), None for other formats. OpenCV returns
    the stored values unscaled and Pillow keeps the header's maximum private, so the header's bytes (their length
    known from Pillow, whatever its comments) are split into magic, width, height, maximum; ``#`` comments run to
    the end of their line."""
    if header.format != "PPM" or header.data_offset <= 0:
        return None
    with image.open("rb") as file:
        head = file.read(header.data_offset)
    fields = re.sub(rb"#[^\r\n]*", b" ", head).split()
    return int(fields[3]) if len(fields) >= 4 and fields[3].isdigit() and int(fields[3]) > 0 else None


def _shade(image: np.ndarray, mode: str, white: float) -> tuple[np.ndarray, np.ndarray]:
    """Pixel shade in [0, 1] (rows, cols) and an opaque mask, as GraphicsMagick gives them to map_server; ``white``
    is the pixel value of full brightness (the type's maximum, or a PGM's declared maximum)."""
    px = image.astype(np.float64) / white
    channels = 1 if px.ndim == 2 else px.shape[2]
    px = px.reshape(*px.shape[:2], channels)
    colour, alpha = (px[..., :-1], px[..., -1]) if channels in (2, 4) else (px, None)
    opaque = np.ones(px.shape[:2], dtype=bool) if alpha is None else alpha >= 1.0
    if mode == "trinary" and alpha is not None:  # map_server averages alpha in, to keep its old behaviour
        return px.mean(axis=2), opaque
    return colour.mean(axis=2), opaque


def _image_header(path: Path, image: Path) -> ImageHeader:
    """The map image's header; MapFileError when it cannot be read before decoding or declares more pixels than
    ``Limits.map_cells``."""
    try:
        header = read_image_header(image, "map image")
    except ValueError as exc:
        raise MapFileError(f"{path}: {exc}") from None
    try:
        detail = f"{header.width} x {header.height} = "
        check_limit("map image", header.width * header.height, "map_cells", "pixels", detail)
    except ValueError as exc:
        raise MapFileError(f"{path}: {image}: {exc}") from None
    return header


def read_map(path: str | Path) -> OccupancyGrid:
    """Load a map_server YAML + image (PGM, PNG, ...) into an OccupancyGrid, exactly as map_server would.

    MapFileError naming the file: unreadable or malformed YAML, a bad field, an image that cannot be read or one
    larger than ``sid.checks.Limits.map_cells`` pixels (refused from its header, before decoding)."""
    path = Path(path)
    meta = _read_metadata(path)
    special = special_file(meta["image"])
    if special:
        raise MapFileError(f"{path}: cannot read map image {meta['image']}: {special}")
    header = _image_header(path, meta["image"])
    image = cv2.imread(str(meta["image"]), cv2.IMREAD_UNCHANGED)
    if image is None or image.size == 0:
        raise MapFileError(f"{path}: cannot read map image {meta['image']} (missing or not an image)")
    if image.dtype not in (np.uint8, np.uint16):
        raise MapFileError(f"{path}: map image {meta['image']} must be 8 or 16 bit, got {image.dtype}")
    white = _netpbm_maxval(meta["image"], header) or (65535.0 if image.dtype == np.uint16 else 255.0)
    shade, opaque = _shade(image, meta["mode"], white)
    occ = shade if meta["negate"] else 1.0 - shade
    free, occupied = meta["free"], meta["occupied"]
    if meta["mode"] == "raw":
        value = np.round(shade * 255)
        data = np.where((value >= 0) & (value <= OCC_OCCUPIED), value, OCC_UNKNOWN)
    else:
        if meta["mode"] == "trinary":
            between = np.full(occ.shape, OCC_UNKNOWN, dtype=float)
        else:
            between = np.where(opaque, np.rint((occ - free) / (occupied - free) * 100.0), OCC_UNKNOWN)
        data = np.where(occ > occupied, OCC_OCCUPIED, np.where(occ < free, 0, between))
        if meta["mode"] == "scale":
            data = np.where(opaque, data, OCC_UNKNOWN)
    rows, cols = data.shape
    try:
        spec = GridSpec(meta["resolution"], meta["origin"][0], meta["origin"][1], cols, rows)
    except ValueError as exc:  # e.g. an origin too far for its cells to be told apart
        raise MapFileError(f"{path}: {exc}") from None
    return OccupancyGrid(spec, np.flipud(data).astype(np.int8), origin_yaw=meta["origin"][2])


def write_map(path: str | Path, grid: OccupancyGrid) -> Path:
    """Write ``grid`` as ``path`` (YAML, mode raw) and a PGM image next to it; returns the image path."""
    path = Path(path)
    if path.suffix not in (".yaml", ".yml"):
        raise MapFileError(f"{path}: a map description must end in .yaml")
    image_path = path.with_suffix(".pgm")
    pixels = np.where(grid.data < 0, np.uint8(255), grid.data.astype(np.uint8))  # unknown (-1) -> 255
    path.parent.mkdir(parents=True, exist_ok=True)
    if not cv2.imwrite(str(image_path), np.flipud(pixels)):
        raise MapFileError(f"{image_path}: cannot write the map image")
    meta = {
        "image": image_path.name,
        "mode": "raw",
        "resolution": grid.spec.resolution,
        "origin": [grid.spec.origin_x, grid.spec.origin_y, float(grid.origin_yaw)],
        "negate": 0,
        "occupied_thresh": 0.65,
        "free_thresh": 0.25,
    }
    path.write_text(yaml.safe_dump(meta, sort_keys=False))
    return image_path

"""Folder source: colour + depth images on disk with a calibration JSON.

Two layouts (the calibration is ``intrinsics.json`` or ``calibration.json`` in the folder, any form
``sid.perception.camera.Calibration.from_json`` reads; a flat intrinsics dict means depth registered to colour):

- one frame: ``DIR/color.png`` (or ``.jpg``/``.jpeg``) + ``DIR/depth.png``;
- a sequence: ``DIR/color/NAME.png|jpg|jpeg`` + ``DIR/depth/NAME.png``, paired by NAME and played in natural order
  (``frame2`` before ``frame10``).

Depth PNGs are single-channel uint16 in depth units (metres = value * depth_scale; 0 = no reading). Colour is any
image OpenCV reads (greyscale, RGBA and 16-bit ones become 8-bit RGB), its pixels as stored (a JPEG's EXIF
orientation is not applied: depth is registered to the stored pixels); frames carry it as RGB. A frame whose files
are missing, unreadable or of the wrong size raises ``FrameReadError`` naming the file (and, for a missing one, any
file of its name in a format not read, e.g. depth in metres as ``1.tiff`` or ``1.npy``), and iteration goes on with
the next frame.
"""

from __future__ import annotations

import glob
import itertools
import re
from concurrent.futures import Future, ThreadPoolExecutor
from pathlib import Path

import cv2
import numpy as np

from sid.documents import image_cut_short, read_image_header, special_file
from sid.errors import InputError
from sid.perception.camera import Calibration
from sid.perception.frame import Frame
from sid.sources import FOLDER_FPS, FrameReadError, SourceError

__all__ = ["CALIBRATION_NAMES", "COLOR_SUFFIXES", "FolderSource"]

COLOR_SUFFIXES = (".png", ".jpg", ".jpeg")
CALIBRATION_NAMES = ("intrinsics.json", "calibration.json")


class FolderSource:
    """Frames from a folder (see the module docstring). ``fps`` only sets timestamps (index / fps seconds).

    ``calibration`` overrides the folder's JSON. ``len(source)`` is the number of frames; ``source.read(i)`` reads
    frame i; iterating reads them in order.
    """

    def __init__(self, path: str | Path, *, calibration: Calibration | None = None, fps: float = FOLDER_FPS) -> None:
        self.path = Path(path)
        if not self.path.is_dir():
            raise SourceError(f"frame folder {self.path} does not exist or is not a directory")
        if not (np.isfinite(fps) and fps > 0):
            raise InputError(f"folder source: fps must be positive, got {fps}")
        self.fps = float(fps)
        self.calibration = calibration if calibration is not None else self._read_calibration()
        self.single = False  # the one-frame layout (DIR/color.png + DIR/depth.png); set by _find_pairs
        self.pairs = self._find_pairs()

    def _read_calibration(self) -> Calibration:
        for name in CALIBRATION_NAMES:
            candidate = self.path / name
            if candidate.exists():  # a FIFO or a device too: Calibration.from_json refuses it by name
                try:
                    return Calibration.from_json(candidate)
                except ValueError as exc:
                    raise SourceError(str(exc)) from None
        raise SourceError(f"frame folder {self.path}: no {' or '.join(CALIBRATION_NAMES)} with the intrinsics")

    def _find_pairs(self) -> list[tuple[str, list[Path], list[Path]]]:
        """(name, colour files, depth files) per frame: one of each, else that frame fails when read (a file
        missing, or two with one name, e.g. ``a.png`` and ``a.jpg``)."""
        single_color = [self.path / f"color{suffix}" for suffix in COLOR_SUFFIXES]
        single_color = [p for p in single_color if p.exists()]
        if single_color or (self.path / "depth.png").exists():
            self.single = True
            depth = self.path / "depth.png"
            return [("color", single_color, [depth] if depth.exists() else [])]
        color_dir, depth_dir = self.path / "color", self.path / "depth"
        if not (color_dir.is_dir() and depth_dir.is_dir()):
            raise SourceError(
                f"frame folder {self.path}: expected color.png + depth.png, or color/ and depth/ subfolders"
            )
        colors: dict[str, list[Path]] = {}
        for path in sorted(color_dir.iterdir()):
            if path.suffix.lower() in COLOR_SUFFIXES:
                colors.setdefault(path.stem, []).append(path)
        depths: dict[str, list[Path]] = {}
        for path in sorted(depth_dir.iterdir()):
            if path.suffix.lower() == ".png":
                depths.setdefault(path.stem, []).append(path)
        names = sorted(colors.keys() | depths.keys(), key=_natural_key)
        if not names:
            raise SourceError(f"frame folder {self.path}: color/ and depth/ hold no images")
        return [(name, colors.get(name, []), depths.get(name, [])) for name in names]

    def __len__(self) -> int:
        return len(self.pairs)

    def read(self, index: int) -> Frame:
        """Frame ``index`` (0-based). Raises FrameReadError naming the file when it cannot be used."""
        name, colors, depths = self.pairs[index]
        if not colors:
            raise FrameReadError(f"frame {name!r}: no colour image {self._missing('color', name)}", index, None)
        if not depths:
            raise FrameReadError(f"frame {name!r}: no depth image {self._missing('depth', name)}", index, None)
        for kind, paths in (("colour", colors), ("depth", depths)):
            if len(paths) > 1:
                names = " and ".join(str(p) for p in paths)
                raise FrameReadError(f"frame {name!r}: {len(paths)} {kind} images, {names}; keep one", index, None)
            special = special_file(paths[0])
            if special:
                raise FrameReadError(f"{kind} image {paths[0]}: {special}", index, paths[0])
        color_path, depth_path = colors[0], depths[0]
        calib = self.calibration
        grid = calib.depth if calib.depth is not None else calib.color
        # both sizes from the headers, before anything is decoded
        color_format = _check_size(color_path, "colour image", calib.color.width, calib.color.height, index)
        registered = "" if calib.depth is not None else _REGISTERED
        depth_format = _check_size(depth_path, "depth image", grid.width, grid.height, index, registered)
        # Decoded straight to RGB (no conversion pass), as stored: depth is registered to the stored pixels, so a
        # JPEG's EXIF orientation, which OpenCV would apply, is not.
        flags = cv2.IMREAD_COLOR_RGB | cv2.IMREAD_IGNORE_ORIENTATION
        rgb = _decode(color_path, "colour image", color_format, flags, index)
        raw = _decode(depth_path, "depth image", depth_format, cv2.IMREAD_UNCHANGED, index)
        if raw.dtype != np.uint16 or raw.ndim != 2:
            raise FrameReadError(
                f"depth image {depth_path} must be single-channel 16-bit (depth units), got {raw.dtype} "
                f"with shape {raw.shape}",
                index,
                depth_path,
            )
        expected_color = (calib.color.height, calib.color.width)
        if rgb.shape[:2] != expected_color:
            raise FrameReadError(
                f"colour image {color_path} is {rgb.shape[1]}x{rgb.shape[0]}, the calibration says "
                f"{calib.color.width}x{calib.color.height}",
                index,
                color_path,
            )
        if raw.shape != (grid.height, grid.width):
            raise FrameReadError(
                f"depth image {depth_path} is {raw.shape[1]}x{raw.shape[0]}, expected {grid.width}x{grid.height}",
                index,
                depth_path,
            )
        depth = raw.astype(np.float32) * np.float32(calib.depth_scale)
        return Frame(index, rgb, depth, calib, index / self.fps)

    def __iter__(self) -> _Reader:
        return _Reader(self)

    def _missing(self, kind: str, name: str) -> str:
        """Where frame ``name``'s ``kind`` image ("color" or "depth") was looked for, and any file of that name in a
        format the folder does not read (depth saved as a float TIFF or ``.npy``, colour as BMP), e.g.
        ``1.png in DIR/depth (DIR/depth/1.npy is not read: ...)``."""
        folder, stem = (self.path, kind) if self.single else (self.path / kind, name)
        suffixes, expected = (
            (COLOR_SUFFIXES, f"{stem}.png, .jpg or .jpeg") if kind == "color" else ((".png",), f"{stem}.png")
        )
        others = [
            path
            for path in sorted(folder.glob(f"{glob.escape(stem)}.*"))
            if path.stem == stem and path.suffix.lower() not in suffixes
        ]
        if not others:
            return f"{expected} in {folder}"
        rule = (
            "colour images are PNG or JPEG"
            if kind == "color"
            else "depth images are single-channel 16-bit PNGs in depth units"
        )
        verb = "is" if len(others) == 1 else "are"
        return f"{expected} in {folder} ({' and '.join(map(str, others))} {verb} not read: {rule})"


class _Reader:
    """Sequential iterator over a FolderSource that survives FrameReadError (it has already moved on).

    While the caller works on a frame, the next one is read in a background thread: OpenCV's PNG decoding releases
    the GIL, so decoding overlaps the pose network and the rest of the frame (docs/benchmarks.md, "Start-up and the
    detect loop"). Frames still come in order, and a read error is raised for its own
    frame.
    """

    def __init__(self, source: FolderSource) -> None:
        self.source = source
        self.index = 0
        self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="sid-folder-read")
        self._ahead: Future[Frame] | None = None  # the read of frame ``index``, when started

    def __iter__(self) -> _Reader:
        return self

    def __next__(self) -> Frame:
        if self.index >= len(self.source):
            self._pool.shutdown(wait=False)
            raise StopIteration
        index = self.index
        self.index += 1
        current = self._ahead or self._pool.submit(self.source.read, index)
        self._ahead = self._pool.submit(self.source.read, self.index) if self.index < len(self.source) else None
        return current.result()


_REGISTERED = (
    " (depth registered to colour has the colour image's size; depth of its own size needs the calibration's depth "
    "and depth_to_color sections)"
)


def _check_size(path: Path, what: str, width: int, height: int, index: int, hint: str = "") -> str:
    """The image's format (``ImageHeader.format``); FrameReadError (``hint`` ending its message) unless its header
    declares the calibration's ``width`` x ``height`` pixels, read before any pixel is decoded (a header of 20000 x
    20000 would make OpenCV allocate gigabytes first)."""
    try:
        header = read_image_header(path, what)
    except ValueError as exc:
        raise FrameReadError(str(exc), index, path) from None
    if (header.width, header.height) != (width, height):
        raise FrameReadError(
            f"{what} {path} is {header.width}x{header.height}, the calibration says {width}x{height}{hint}", index, path
        )
    return header.format


def _decode(path: Path, what: str, format: str, flags: int, index: int) -> np.ndarray:
    """The pixels of the image file ``path`` of ``format``, decoded with OpenCV's imread ``flags``; FrameReadError
    when it cannot be read, is cut short (a JPEG would decode in part, the rest grey) or does not decode."""
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise FrameReadError(f"cannot read {what} {path} ({exc.strerror or exc})", index, path) from None
    if image_cut_short(data, format):
        raise FrameReadError(f"{what} {path} is cut short: it ends before the image does", index, path)
    image = cv2.imdecode(np.frombuffer(data, np.uint8), flags)
    if image is None:
        raise FrameReadError(f"cannot read {what} {path}", index, path)
    return image


def _natural_key(name: str) -> list[int | str]:
    """``name`` split into text and runs of ASCII digits (read as numbers): any name sorts, ``².png`` too."""
    return [int(part) if odd else part.lower() for odd, part in zip(itertools.cycle((0, 1)), _DIGITS.split(name))]


_DIGITS = re.compile("([0-9]+)")  # ASCII only: str.isdigit also accepts "²", which int() refuses

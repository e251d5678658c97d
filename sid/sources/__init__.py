"""Frame sources: everything that yields ``sid.perception.frame.Frame`` (colour + depth + calibration).

``open_source(spec)`` picks one from a string, as ``sid detect --source`` does:

- ``"realsense"``: a live RealSense camera (``sid.sources.realsense.RealSenseSource``);
- ``"FILE.db3"`` / ``"FILE.bag"``: a RealSense recording (librealsense 2.59+ writes .db3, older versions .bag);
- ``"FILE.db3"`` / ``"FILE.mcap"`` / a rosbag2 folder (with ``metadata.yaml``): a ``ros2 bag record`` of
  realsense2_camera topics (``sid.sources.rosbag2.Rosbag2Source``), and ``"FILE.bag"``, a ROS 1 ``rosbag record``
  of them; a .db3 or .bag is librealsense's when its topics live under ``/device_N/``; the storage file of a
  compressed rosbag2 recording (``ros2 bag record --compression-mode``) is read through its folder's
  ``metadata.yaml``, which says how it was compressed;
- a directory: a folder of colour + depth images (``sid.sources.folder.FolderSource``);
- ``"synthetic:SCENARIO"``: rendered people (``sid.sources.synthetic``).

Sources are iterators. A frame that cannot be read raises ``FrameReadError`` from ``next()`` and the source moves
on to the next frame, so a caller can report it and continue (``skip_unreadable`` does exactly that). A source that
cannot be opened at all, or breaks for good (camera unplugged), raises ``SourceError``.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from pathlib import Path
from typing import Any

from sid.documents import special_file
from sid.errors import SidError
from sid.perception.frame import Frame

__all__ = [
    "BAG_TOPICS",
    "FOLDER_FPS",
    "FrameReadError",
    "RECORDING_SUFFIXES",
    "ROSBAG2_METADATA",
    "SourceError",
    "frames_or_errors",
    "is_frame_folder",
    "open_source",
    "skip_unreadable",
]

RECORDING_SUFFIXES = (".db3", ".bag", ".mcap")
ROSBAG2_METADATA = "metadata.yaml"
BAG_TOPICS = ("color_topic", "depth_topic", "info_topic")
"""The options of a rosbag2 source that choose its topics (``sid.sources.rosbag2.Rosbag2Source``)."""
FOLDER_FPS = 30.0
"""Frames per second a folder's frames are stamped at unless told (``fps``; its files carry no time)."""


class SourceError(SidError, RuntimeError):
    """A source cannot be opened or cannot go on (no camera, unreadable recording, missing folder)."""


class FrameReadError(SourceError):
    """One frame could not be read; the source has moved past it and the next ``next()`` may succeed.

    index: the frame's position in the source (0-based); path: the file at fault, when there is one.
    """

    def __init__(self, message: str, index: int | None = None, path: Path | None = None) -> None:
        super().__init__(message)
        self.index = index
        self.path = path


def open_source(spec: str, **options: Any) -> Iterable[Frame]:
    """The source named by ``spec`` (see the module docstring); ``options`` go to that source's constructor. The
    topic options of ``BAG_TOPICS`` (None: not given) are for rosbag2 recordings; SourceError for another source."""
    if not isinstance(spec, str) or not spec:
        raise SourceError("source: empty spec; use realsense, FILE.db3, FILE.bag, FILE.mcap, DIR or synthetic:SCENARIO")
    given = {name: options.pop(name, None) for name in BAG_TOPICS}
    topics = {name: topic for name, topic in given.items() if topic is not None}
    if topics and not _is_rosbag2(Path(spec)):
        named = ", ".join(f"--{name.replace('_', '-')}" for name in topics)
        raise SourceError(f"{named}: only rosbag2 recordings have topics to choose, and {spec} is not one")
    options |= topics
    if spec.startswith("synthetic:"):
        from sid.sources.synthetic import synthetic_source

        return synthetic_source(spec, **options)
    if spec == "realsense":
        return _realsense()(None, **options)
    path = Path(spec)
    if path.is_file() and _compressed_bag_file(path):
        return _rosbag2(path.parent, options)
    if path.suffix.lower() in RECORDING_SUFFIXES:
        if not path.exists():
            raise SourceError(f"recording {path} does not exist")
        special = special_file(path)
        if special:
            raise SourceError(f"recording {path}: {special}")
        if _librealsense_recording(path):
            return _realsense()(path, **options)
        return _rosbag2(path, options)
    if (path / ROSBAG2_METADATA).exists():
        return _rosbag2(path, options)
    if is_frame_folder(path):
        _refuse_bare_bag_folder(path)
        from sid.sources.folder import FolderSource

        return FolderSource(path, **options)
    if not path.exists():
        raise SourceError(f"source {spec!r}: no such file or directory (use realsense, FILE.db3, DIR, synthetic:...)")
    raise SourceError(f"source {spec!r}: not a recording (.db3/.bag/.mcap), a rosbag2 folder or a folder of frames")


def is_frame_folder(path: Path) -> bool:
    """Whether ``open_source`` reads ``path`` as a folder of frames (``sid.sources.folder``)."""
    return path.is_dir() and not (path / ROSBAG2_METADATA).exists()


def _is_rosbag2(path: Path) -> bool:
    """Whether ``open_source`` reads ``path`` as a rosbag2 recording."""
    if (path / ROSBAG2_METADATA).exists() or (path.is_file() and _compressed_bag_file(path)):
        return True
    return path.suffix.lower() in RECORDING_SUFFIXES and path.is_file() and not _librealsense_recording(path)


def _compressed_bag_file(path: Path) -> bool:
    """Whether ``path`` is a storage file of a compressed rosbag2 recording with its ``metadata.yaml`` beside it:
    only the folder says how its messages (or the file) were compressed."""
    from sid.sources.rosbag2 import compressed_bag_files

    return path.name in compressed_bag_files(path.parent)


def _librealsense_recording(path: Path) -> bool:
    """A .db3 or .bag written by librealsense, or one rosbags cannot read (librealsense then has the last word); a
    .db3 that is not a readable SQLite database at all (cut short, overwritten) is refused here, naming the
    problem."""
    from sid.sources.rosbag2 import is_librealsense_recording, sqlite_problem

    suffix = path.suffix.lower()
    try:
        return suffix in (".db3", ".bag") and is_librealsense_recording(path)
    except SourceError:
        if suffix == ".bag":
            return True
        problem = sqlite_problem(path)
        if problem:
            raise SourceError(
                f"recording {path}: not a readable SQLite database ({problem}); the file is damaged or incomplete"
            ) from None
        return True


def _refuse_bare_bag_folder(path: Path) -> None:
    """SourceError for a folder holding rosbag2 storage files but no metadata.yaml (not a frame folder either)."""
    if any((path / name).exists() for name in ("color", "depth", "color.png", "depth.png")):
        return
    bags = sorted(p.name for p in path.iterdir() if p.suffix.lower() in (".db3", ".mcap"))
    if bags:
        raise SourceError(
            f"{path}: holds {', '.join(bags[:3])}{' ...' if len(bags) > 3 else ''} but no {ROSBAG2_METADATA}, so it "
            f"is not a rosbag2 folder (nor a folder of frames); give the file itself (--source {path / bags[0]}) "
            f"or rebuild the metadata with `ros2 bag reindex {path}`"
        )


def _rosbag2(path: Path, options: dict[str, Any]) -> Iterable[Frame]:
    """A ``Rosbag2Source``. realsense2_camera bags carry depth already aligned to colour, so the RealSense sources'
    ``align`` option (which ``sid detect`` passes to every recording) has nothing to choose and is dropped."""
    from sid.sources.rosbag2 import Rosbag2Source

    options.pop("align", None)
    return Rosbag2Source(path, **options)


def _realsense() -> Any:
    """``sid.sources.realsense.RealSenseSource``, imported only now: pyrealsense2 loads only when a RealSense source
    is opened, and a SourceError says why when it cannot load (not installed, or no libusb-1.0 on the system)."""
    try:
        from sid.sources.realsense import RealSenseSource
    except (ImportError, OSError) as exc:
        raise SourceError(
            f"RealSense sources need pyrealsense2, which cannot be loaded ({exc}); install it with "
            "`pip install pyrealsense2` and the system library libusb-1.0-0 (`sudo apt-get install libusb-1.0-0`)"
        ) from None
    return RealSenseSource


def frames_or_errors(source: Iterable[Frame]) -> Iterator[Frame | FrameReadError]:
    """The frames of ``source`` and, in their place, the ``FrameReadError`` of each unreadable one (not raised):
    for a caller that hands the reading to another thread and reports errors in order."""
    frames = iter(source)
    while True:
        try:
            frame = next(frames)
        except StopIteration:
            return
        except FrameReadError as error:
            yield error
            continue
        yield frame


def skip_unreadable(source: Iterable[Frame], on_error: Callable[[FrameReadError], None]) -> Iterator[Frame]:
    """Frames of ``source``; each unreadable one is passed to ``on_error`` (e.g. to log it) and skipped."""
    for item in frames_or_errors(source):
        if isinstance(item, FrameReadError):
            on_error(item)
        else:
            yield item

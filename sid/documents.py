"""Reading the project's JSON / YAML input files (scenarios, scenes) with one rule and one set of errors, the headers
of image files before their pixels, writing output files whole (a temporary file in the same folder, then a
rename), and counting nouns in output text."""

from __future__ import annotations

import json
import math
import os
import re
import reprlib
import secrets
import stat
import struct
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TypeGuard

import yaml

from sid.errors import InputError

__all__ = [
    "IMAGE_FORMATS",
    "ImageHeader",
    "InputWarning",
    "TEMPORARY_PREFIX",
    "decode_text",
    "image_cut_short",
    "is_number",
    "load_document",
    "read_image_header",
    "special_file",
    "summary",
    "unique_keys",
    "write_atomically",
    "plural",
]


class InputWarning(UserWarning):
    """An input sid accepts but changes (e.g. a map sampled onto other cells); ``sid`` prints it on one line."""


def load_document(path: str | Path, kind: str = "file") -> Any:
    """Parsed content of a ``.json`` file (JSON) or any other file (YAML, which also reads JSON).

    Raises ValueError naming the file and ``kind`` (what the file should be): unreadable, not UTF-8 text (a
    byte-order mark is allowed), not valid JSON / YAML, or nested too deeply to parse.
    """
    path = Path(path)
    special = special_file(path)
    if special:
        raise InputError(f"{path}: cannot read {kind}: {special}")
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise InputError(f"{path}: cannot read {kind} ({exc.strerror or exc})") from None
    text = decode_text(raw, f"{path}: cannot read {kind}")
    is_json = path.suffix.lower() == ".json"
    try:
        return json.loads(text, object_pairs_hook=unique_keys) if is_json else yaml.load(text, _UniqueKeyLoader)
    except RecursionError:
        raise InputError(f"{path}: cannot read {kind}: nested too deeply") from None
    except (json.JSONDecodeError, yaml.YAMLError, ValueError, TypeError, OverflowError) as exc:
        # Besides syntax errors, YAML's constructors raise ValueError for values such as `2001-02-30` or `!!int 0xZZ`.
        # PyYAML's messages span lines and name "<unicode string>": made one line here.
        reason = " ".join(str(exc).split()).replace(' in "<unicode string>",', " at")
        raise InputError(f"{path}: not valid {'JSON' if is_json else 'YAML'} ({reason})") from None


_SPECIAL_FILES = (
    (stat.S_ISFIFO, "a FIFO (named pipe)"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
    (stat.S_ISDIR, "a folder"),
)


def special_file(path: str | Path, *, streams: bool = False) -> str | None:
    """``"it is a FIFO (named pipe), not a regular file"`` (or a device, a socket, a folder) when ``path`` exists and
    is not a regular file or a link to one; None otherwise (a missing file is left to the reader's open). Readers
    refuse these before opening them: opening a FIFO blocks until something writes to it, and a device such as
    /dev/zero never ends. ``streams``: FIFOs and sockets pass, for a reader that reads a stream with a bound."""
    try:
        mode = os.stat(path).st_mode
    except (OSError, ValueError):  # missing, unreadable, or a name with a NUL byte: the open says so
        return None
    if streams and (stat.S_ISFIFO(mode) or stat.S_ISSOCK(mode)):
        return None
    for test, name in _SPECIAL_FILES:
        if test(mode):
            return f"it is {name}, not a regular file"
    return None


def unique_keys(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    """A JSON object's pairs as a dict; ValueError on a key given twice (json.loads would keep the last silently)."""
    result: dict[str, Any] = {}
    for key, value in pairs:
        if key in result:
            raise InputError(f"duplicate key {key!r}")
        result[key] = value
    return result


class _UniqueKeyLoader(yaml.SafeLoader):
    """PyYAML's safe loader, refusing a mapping that gives a key twice (it would keep the last silently); keys
    brought in by a ``<<`` merge may still be overridden, as YAML intends. A number with an exponent and no point
    (``5e-2``, ``1E3``) is a float, as in YAML 1.2 and in the yaml-cpp reader of Nav2's map_server (YAML 1.1, which
    PyYAML follows, makes it a string)."""

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict[Any, Any]:
        seen: set[Any] = set()
        for key_node, _ in node.value:
            if key_node.tag == "tag:yaml.org,2002:merge":
                continue
            key = self.construct_object(key_node, deep=deep)
            try:
                duplicate = key in seen
            except TypeError:  # an unhashable key: the safe loader refuses it below
                continue
            if duplicate:
                raise yaml.constructor.ConstructorError(None, None, f"found duplicate key {key!r}", key_node.start_mark)
            seen.add(key)
        return super().construct_mapping(node, deep)


_UniqueKeyLoader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(r"^[-+]?(?:[0-9][0-9_]*(?:\.[0-9_]*)?|\.[0-9][0-9_]*)[eE][-+]?[0-9]+$"),
    list("-+0123456789."),
)


def _printable(text: str) -> str:
    """``text`` with every character that is not printable written as its JSON escape (``\\u0085``): JSON escapes
    only the C0 controls, while U+0085 and U+2028/9 end a line for ``str.splitlines`` (and for log readers), a C1
    control such as U+009B may drive a terminal, and format characters (U+200B, U+FEFF) are invisible."""
    if text.isprintable():
        return text
    return "".join(ch if ch.isprintable() else json.dumps(ch)[1:-1] for ch in text)


def summary(value: Any, limit: int = 80) -> str:
    """A parsed JSON / YAML value written as JSON (``null``, ``[525]``, ``"abc"``) for an error message, on one
    printable line, cut to ``limit`` characters. Only as much of the value is visited as is written, so a value that
    is huge once expanded (a YAML alias bomb: a few hundred bytes naming one list thousands of times over) stays short
    and cheap."""
    parts: list[str] = []
    room = limit + 1  # one past the limit: the text was cut

    def put(text: str) -> None:
        nonlocal room
        parts.append(text[:room])
        room -= len(text)

    def walk(item: Any) -> None:
        if room <= 0:
            return
        if isinstance(item, dict | list | tuple):
            pairs = item.items() if isinstance(item, dict) else ((None, v) for v in item)
            put("{" if isinstance(item, dict) else "[")
            for i, (key, v) in enumerate(pairs):
                if room <= 0:
                    return
                put(", " if i else "")
                if isinstance(item, dict):
                    walk(key if isinstance(key, str) else str(key))
                    put(": ")
                walk(v)
            put("}" if isinstance(item, dict) else "]")
        elif isinstance(item, str):
            put(_printable(json.dumps(item[:room], ensure_ascii=False)))
        else:
            try:
                put(json.dumps(item))
            except (TypeError, ValueError):  # not JSON (a YAML date, an int beyond str's digit limit)
                put(reprlib.repr(item))

    walk(value)
    text = "".join(parts)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def decode_text(raw: bytes, what: str) -> str:
    """``raw`` decoded as UTF-8 (a leading byte-order mark dropped); ValueError ``"what: ..."`` naming the first
    byte that is not UTF-8 and where it is (line and byte offset), e.g. for a binary file."""
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = raw.count(b"\n", 0, exc.start) + 1
        raise InputError(
            f"{what}: byte 0x{raw[exc.start]:02x} at offset {exc.start} (line {line}) is not UTF-8 text"
        ) from None


def is_number(value: Any) -> TypeGuard[int | float]:
    """Whether a parsed JSON / YAML value is a finite number (an int or a float; booleans do not count, nor an int
    too large for a float, e.g. 400 digits)."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        return False
    try:
        return math.isfinite(value)
    except OverflowError:  # an int beyond the float range
        return False


IMAGE_FORMATS = ("PNG", "JPEG", "PPM", "BMP", "TIFF")
"""Pillow's names of the image formats sid reads (PPM includes PGM): those whose size Pillow reads from the header
without decoding a pixel, so it can be checked before OpenCV allocates the image."""


@dataclass(frozen=True)
class ImageHeader:
    """What an image file's header declares: Pillow's format name, width and height (pixels), and the offset
    (bytes) where its pixels start, the header's length (0 when the format stores them in several blocks)."""

    format: str
    width: int
    height: int
    data_offset: int


def read_image_header(path: str | Path, what: str) -> ImageHeader:
    """The header of an image file, read without decoding any pixel; ValueError ``"... what PATH ..."`` when the
    file cannot be read or is not one of ``IMAGE_FORMATS`` (e.g. Radiance .hdr, PAM, OpenEXR: OpenCV would allocate
    whatever their headers say before any size could be checked).

    Pillow's parser of the format, found as ``Image.open`` finds it, reads the header; ``Image.open`` itself would
    refuse a header above its own pixel bound with a message that hides the size."""
    from PIL import Image  # Pillow's import only where an image is read

    Image.init()
    try:
        with open(path, "rb") as file:
            prefix = file.read(16)
            for name in IMAGE_FORMATS:
                factory, accept = Image.OPEN[name]
                if accept is not None and not accept(prefix):
                    continue
                file.seek(0)
                image = factory(file, str(path))
                tiles = image.tile
                offset = int(tiles[0][2]) if len(tiles) == 1 else 0
                return ImageHeader(name, image.size[0], image.size[1], offset)
    except OSError as exc:  # missing, unreadable, or truncated within its header
        raise InputError(f"cannot read {what} {path} ({str(exc.strerror or exc)[:120]})") from None
    except (SyntaxError, ValueError, EOFError, struct.error) as exc:  # a header the format's parser refuses
        raise InputError(f"cannot read {what} {path}: bad header ({str(exc)[:120]})") from None
    raise InputError(
        f"cannot read {what} {path}: not a PNG, JPEG, PGM/PPM, BMP or TIFF image (the formats whose size sid reads "
        "before decoding)"
    )


def image_cut_short(data: bytes, format: str) -> bool:
    """Whether the encoded image ``data``, of Pillow's ``format`` name (``ImageHeader.format``), ends before its
    end: a PNG without its whole IEND chunk, a JPEG without an end-of-image marker after its first scan starts (its
    header's segments, an EXIF thumbnail's own marker among them, are skipped by their lengths; within the scans, FF
    D9 is that marker and nothing else). A cut JPEG would otherwise decode in part (OpenCV greys the rest, with a
    libjpeg warning on stderr); a cut PNG fails in libpng. Bytes after the end do not count; other formats are not
    checked (False)."""
    if format == "PNG":
        end = data.rfind(b"\0\0\0\0IEND")  # the last chunk: no data, then its 4-byte CRC
        return end < 0 or len(data) < end + 12
    if format != "JPEG":
        return False
    pos = 2  # after the start-of-image marker
    while pos + 3 < len(data) and data[pos] == 0xFF:
        marker = data[pos + 1]
        if marker == 0xFF:  # a fill byte
            pos += 1
            continue
        pos += 2 + int.from_bytes(data[pos + 2 : pos + 4], "big")  # the segment, its length included
        if marker == 0xDA:  # the first scan: its data, and any later scan, end at the end-of-image marker
            return data.rfind(b"\xff\xd9", pos) < 0  # from the end: at once for a whole file
    return True  # the header is cut, or not a run of segments


def plural(count: int, singular: str, plural_form: str | None = None) -> str:
    """``count`` and the noun it takes in messages and reports: ``1 group``, ``2 groups``, ``1 person`` (with
    ``plural_form="people"``), ``0 people``."""
    return f"{count} {singular if count == 1 else (plural_form or singular + 's')}"


TEMPORARY_PREFIX = ".sid-partial-"
"""Names of the temporary files and folders sid writes outputs through; a killed run may leave one behind."""


def write_atomically(path: str | Path, data: bytes) -> Path:
    """Write ``data`` to ``path`` whole or not at all: into a temporary file in the same folder, then
    ``os.replace`` (atomic on POSIX and Windows), so a reader never sees a half-written file, even after a kill.
    The file gets the permissions the user's umask gives a new file, as ``open`` would (not mkstemp's 0600)."""
    path = Path(path)
    while True:
        temporary = path.parent / f"{TEMPORARY_PREFIX}{secrets.token_hex(6)}"
        try:
            handle = os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0), 0o666)
            break
        except FileExistsError:  # another writer's temporary file of the same name: draw again
            continue
    try:
        with os.fdopen(handle, "wb") as file:
            file.write(data)
        os.replace(temporary, path)
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise
    return path

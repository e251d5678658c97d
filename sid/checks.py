"""Checks of the numbers in parameter records, with one error message format: ``"owner: name must be ..., got v"``,
and the size limits of inputs (``Limits``), checked where a value enters and before anything is allocated for it.

Records call these from ``__post_init__`` so that a bad value fails where it is set, naming the field.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import numbers
import os
from collections import Counter
from collections.abc import Hashable, Iterable, Iterator, Sequence
from dataclasses import dataclass
from typing import Any, TypeVar

from sid.errors import InputError, SidError

__all__ = [
    "LIMITS_ENV",
    "LimitError",
    "MAX_COORDINATE",
    "MAX_LENGTH",
    "Limits",
    "YAW_LIMIT_RAD",
    "amount",
    "check_limit",
    "check_number",
    "check_numbers",
    "check_whole",
    "check_yaw",
    "check_yaws",
    "is_real",
    "limits",
    "limits_from_environment",
    "repeated",
    "use_limits",
]

_H = TypeVar("_H", bound=Hashable)

LIMITS_ENV = "SID_LIMITS"
"""The environment variable that raises (or lowers) limits: ``SID_LIMITS="map_cells=16000000,people=300"``."""

MAX_COORDINATE = 1e8
"""The largest |x| or |y| (m) of a person's position: 100 000 km, beyond any map frame on Earth (UTM northings reach
1e7 m). Squared and summed, such coordinates stay finite and precise to about 1e-8 m; past ~1e154 m a squared
distance overflows to infinity and the answers would be silent garbage."""
MAX_LENGTH = 1e3
"""The longest length (m) a group detector's constant may be (an o-space radius or cost length, GCFF's stride), a
kilometre: far beyond any conversation. Squared and summed downstream, bounded constants stay finite."""
YAW_LIMIT_RAD = 4 * math.pi
"""No yaw in radians is written beyond two turns (an unwrapped ``a + pi`` stays well within); a yaw beyond is in
degrees, most likely (a quarter turn written 90)."""


@dataclass(frozen=True)
class Limits:
    """The largest inputs sid accepts; each bounds the memory and time one value can make a command spend.

    What the largest accepted inputs cost in memory and time is measured in docs/parameters.md, "Input limits".

    map_cells: cells of a grid (a scenario's map, a map image's pixels); 4e6 is 100 x 100 m at 5 cm.
    lidar_beams: beams of a simulated scan.
    scan_cells: beams x the longest LiDAR range in cells (``lidar.range_max`` or ``raytrace_max_range``), the
    samples a simulated scan and the LiDAR layer's ray tracing take (720 beams x 10 m at 5 cm: 144000).
    people: people in one frame (a scenario, a ``sid groups`` or ``sid track`` line, a frame of an F-formation
    dataset); grouping time grows faster than the square.
    detections: people the pose model reports in one frame (the highest-scoring are kept, as Ultralytics'
    ``max_det``); the same default as ``people``, whom they become.
    obstacle_points: the points of a scenario's obstacles together (a wall's points, 4 per box, 1 per circle).
    scan_edges: beams x (straight obstacle edges + circles + people), the ray tests of a simulated scan.
    image_pixels: pixels of a camera's image (its calibration's width x height; 33 177 600 is 8K UHD), which every
    frame is decoded at.
    sim_steps: steps of one ``sid simulate`` run, ``time_limit_s`` x ``rate_hz`` (each step's people are kept).
    replay_frames: frames of one trajectory set replayed at a rate (``sid eval crowd --rate``): its time span x the
    rate (each frame's tracks are kept); the public ETH/UCY sets at the largest rate, 1000 Hz, need up to 773 401.
    Raise one with ``SID_LIMITS="NAME=VALUE,..."`` (an environment variable the command line reads when it starts;
    ``use_limits`` from Python).
    """

    map_cells: int = 4_000_000
    lidar_beams: int = 100_000
    scan_cells: int = 20_000_000
    people: int = 100
    detections: int = 100
    obstacle_points: int = 100_000
    scan_edges: int = 20_000_000
    sim_steps: int = 6_000
    replay_frames: int = 1_000_000
    image_pixels: int = 33_177_600


class LimitError(SidError, ValueError):
    """An input above a limit of ``Limits``; the message names the field, the value, the limit and how to raise it."""


_IN_FORCE: list[Limits] = [Limits()]  # the limits every check applies: one process-wide value, set by use_limits


def limits() -> Limits:
    """The limits in force: ``Limits()`` unless an entry point (the command line: ``$SID_LIMITS``) or the caller set
    others with ``use_limits``."""
    return _IN_FORCE[-1]


@contextlib.contextmanager
def use_limits(value: Limits) -> Iterator[Limits]:
    """The limits every check applies within the block, process-wide, then those before it again: ``sid.cli.main``
    runs each command under ``use_limits(limits_from_environment())``; a program embedding sid calls it likewise."""
    _IN_FORCE.append(value)
    try:
        yield value
    finally:
        _IN_FORCE.pop()


def limits_from_environment() -> Limits:
    """``Limits()`` with the values of ``$SID_LIMITS`` (``NAME=VALUE`` pairs, comma-separated; ValueError naming the
    variable for a malformed one). Read by the entry points, once, not by the checks."""
    text = os.environ.get(LIMITS_ENV, "").strip()
    if not text:
        return Limits()
    names = [f.name for f in dataclasses.fields(Limits)]
    values: dict[str, int] = {}
    for item in text.split(","):
        name, _, value = (part.strip() for part in item.partition("="))
        if name not in names:
            raise InputError(f"${LIMITS_ENV}: unknown limit {name!r} in {text!r}; known limits: {', '.join(names)}")
        if name in values:  # as a key given twice in a file: which one was meant?
            raise InputError(f"${LIMITS_ENV}: {name} is given twice in {text!r}")
        try:
            number = float(value)
        except ValueError:
            number = math.nan
        if not (math.isfinite(number) and number >= 1 and number == int(number)):
            raise InputError(f"${LIMITS_ENV}: {name} must be a whole number >= 1, got {value!r}")
        values[name] = int(number)
    return Limits(**values)


def check_number(
    owner: str,
    name: str,
    value: float,
    *,
    low: float | None = None,
    high: float | None = None,
    low_open: bool = False,
    high_open: bool = False,
    allow_inf: bool = False,
    unit: str = "",
    error: type[Exception] = InputError,
) -> None:
    """Raise ``error`` unless ``value`` is a finite real number (``is_real``: not a bool, a string or bytes) within
    [low, high] (bounds optional).

    low_open / high_open exclude that bound; allow_inf also accepts +inf (a switch-off value, e.g. a radius);
    unit (e.g. "metres") only words the message.
    """
    number = float(value) if is_real(value) else math.nan
    ok = math.isfinite(number) or (allow_inf and number == math.inf)
    ok = ok and (low is None or (number > low if low_open else number >= low))
    ok = ok and (high is None or (number < high if high_open else number <= high))
    if not ok:
        shown = value if is_real(value) else repr(value)  # a string "0.8" must not read as the number 0.8
        raise error(f"{owner}: {name} must be {_rule(low, high, low_open, high_open, allow_inf, unit)}, got {shown}")


def is_real(value: object) -> bool:
    """Whether ``value`` is a real number (Python's or numpy's int or float; not a bool, numpy's or Python's, a string
    or None). NaN and infinities are real numbers here: finiteness is checked apart, with its own message."""
    # float and int first: the abstract-class check costs several times more, and people are checked every frame
    exact = type(value) is float or type(value) is int
    return exact or (isinstance(value, numbers.Real) and not isinstance(value, bool))


def check_whole(
    owner: str,
    name: str,
    value: object,
    *,
    low: int | None = None,
    high: int | None = None,
    error: type[Exception] = InputError,
) -> int:
    """``value`` as an int; raise ``error`` unless it is a whole number (an integer, or a real number without a
    fraction; not a bool, not a string) within [low, high] (bounds optional). NaN and infinities get the same
    message, not a conversion error."""
    number = float(value) if isinstance(value, numbers.Real) and not isinstance(value, bool) else math.nan
    ok = math.isfinite(number) and number == math.floor(number)
    ok = ok and (low is None or number >= low) and (high is None or number <= high)
    if not ok:
        if low is not None and high is not None:
            rule = f"a whole number from {low} to {high}"
        elif low is not None:
            rule = f"a whole number >= {low}"
        elif high is not None:
            rule = f"a whole number <= {high}"
        else:
            rule = "a whole number"
        raise error(f"{owner}: {name} must be {rule}, got {value!r}")
    return int(number)


def check_yaw(owner: str, name: str, value: float, error: type[Exception] = InputError) -> None:
    """Raise ``error`` unless ``value`` is a yaw within two turns of 0 (``YAW_LIMIT_RAD``): 90 or 180 is a facing in
    degrees, which read as radians points anywhere. ``value`` is a finite number already."""
    if abs(value) > YAW_LIMIT_RAD:
        raise error(f"{owner}: {name} {value:g} is beyond two turns (4 pi): radians expected, not degrees")


def check_yaws(owner: str, record: object, names: Iterable[str], error: type[Exception] = InputError) -> None:
    """``check_number`` then ``check_yaw`` on each attribute of ``record`` named in ``names`` (radians)."""
    for name in names:
        value = getattr(record, name)
        check_number(owner, name, value, unit="radians", error=error)
        check_yaw(owner, name, value, error)


def check_numbers(owner: str, record: object, names: Iterable[str], **bounds: Any) -> None:
    """``check_number`` on each attribute of ``record`` named in ``names`` (same bounds for all)."""
    for name in names:
        check_number(owner, name, getattr(record, name), **bounds)


def _rule(low: float | None, high: float | None, low_open: bool, high_open: bool, allow_inf: bool, unit: str) -> str:
    """The accepted range in words, e.g. "a positive number of metres" or "a finite number in [0, 1)"."""
    number = ("a number" if allow_inf else "a finite number") + (f" of {unit}" if unit else "")
    if low == 0 and low_open and high is None:
        number = number.replace("a ", "a positive ", 1).replace("finite ", "")
    elif low is not None and high is not None:
        number += f" in {'(' if low_open else '['}{low:g}, {high:g}{')' if high_open else ']'}"
    elif low is not None:
        number += f" {'>' if low_open else '>='} {low:g}"
    elif high is not None:
        number += f" {'<' if high_open else '<='} {high:g}"
    return number + (" (or inf)" if allow_inf else "")


def check_limit(field: str, count: float, limit: str, unit: str, detail: str = "") -> None:
    """Raise LimitError when ``count`` (of ``unit``, e.g. cells) exceeds the limit named ``limit``.

    ``field`` names the input (e.g. "map.size") and ``detail`` how the count arises (e.g. "20000 x 20000 = "); the
    message gives the count, the limit and the variable that raises it.
    """
    allowed = getattr(limits(), limit)
    if not count <= allowed:
        raise LimitError(
            f"{field}: {detail}{amount(count)} {unit} is more than the limit of {allowed:,} {unit} ({limit}; raise "
            f"it with {LIMITS_ENV}={limit}=N)"
        )


def amount(count: float) -> str:
    """A count for a message: with thousands separators (``20,000,000``), in three digits past 10^15 (``2e+304``),
    so that a number from a file cannot make the message long."""
    return f"{count:,.0f}" if count < 1e15 else f"{count:.3g}"


def repeated(items: Sequence[_H]) -> _H | None:
    """The first of ``items`` (in their order) that is given more than once, None when no item is: a name given
    twice to a command would have its runs pooled into one row or counted twice."""
    counts = Counter(items)
    return next((item for item in items if counts[item] > 1), None)

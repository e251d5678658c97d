"""Checks of the numbers in parameter records, with one error message format: ``"owner: name must be ..., got v"``.

Records call these from ``__post_init__`` so that a bad value fails where it is set, naming the field.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import Any


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
    error: type[Exception] = ValueError,
) -> None:
    """Raise ``error`` unless ``value`` is a finite number within [low, high] (bounds optional).

    low_open / high_open exclude that bound; allow_inf also accepts +inf (a switch-off value, e.g. a radius);
    unit (e.g. "metres") only words the message.
    """
    try:
        number = float(value)
    except (TypeError, ValueError):
        number = math.nan
    ok = math.isfinite(number) or (allow_inf and number == math.inf)
    ok = ok and (low is None or (number > low if low_open else number >= low))
    ok = ok and (high is None or (number < high if high_open else number <= high))
    if not ok:
        raise error(f"{owner}: {name} must be {_rule(low, high, low_open, high_open, allow_inf, unit)}, got {value}")


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

"""One person of a JSON line's ``people`` list, as ``sid groups`` and ``sid track`` read it."""

from __future__ import annotations

from typing import Any

from sid.checks import check_yaw
from sid.cli.common import refuse_unknown_fields
from sid.documents import is_number, summary
from sid.errors import InputError
from sid.perception.people import Person

__all__ = ["parse_person"]


def parse_person(data: Any, index: int, fields: tuple[str, ...], *, id_default: bool = False) -> Person:
    """The person at ``index`` of a line's ``people`` list (ground frame: x, y in metres; theta in radians, null or
    absent when unknown; orientation_quality in [0, 1], default 1 with a facing and 0 without, when ``fields``
    holds it); id an integer (a whole float such as 3.0 counts as one). ``fields``: the keys the command reads (any
    other is refused); ``id_default``: a missing id is ``index``. ValueError naming the entry and the key."""
    where = f"people[{index}]"
    if not isinstance(data, dict):
        raise InputError(f"{where} must be an object with {', '.join(fields)}")
    refuse_unknown_fields(data, fields, f"{where}: ")
    if "id" not in data and not id_default:
        raise InputError(f"{where} is missing 'id'")
    person_id = data.get("id", index)
    if isinstance(person_id, float) and person_id.is_integer() and abs(person_id) <= 2**53:
        person_id = int(person_id)  # 3.0: a writer that keeps every number a float (a pandas column), not a fraction
    if isinstance(person_id, bool) or not isinstance(person_id, int):
        raise InputError(f"{where}: id must be an integer, got {summary(person_id)}")
    where = f"{where} (id {person_id})"
    for key in ("x", "y"):
        if key not in data:
            raise InputError(f"{where} is missing {key!r}")
        if not is_number(data[key]):
            raise InputError(f"{where}: {key} must be a finite number of metres, got {summary(data[key])}")
    theta = data.get("theta")
    if theta is not None:
        if not is_number(theta):
            raise InputError(
                f"{where}: theta must be a finite number of radians, or null when unknown, got {summary(theta)}"
            )
        check_yaw(where, "theta", theta)
    quality = data.get("orientation_quality")
    if quality is None:  # a given facing is taken at full quality unless the line says otherwise
        quality = 0.0 if theta is None else 1.0
    elif not (is_number(quality) and 0.0 <= quality <= 1.0):
        raise InputError(f"{where}: orientation_quality must be a number in [0, 1], got {summary(quality)}")
    return Person(person_id, float(data["x"]), float(data["y"]), None if theta is None else float(theta), quality)

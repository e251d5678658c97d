"""The one reader of a JSON line's person, shared by ``sid groups`` and ``sid track``."""

from __future__ import annotations

import pytest

from sid.cli.person_json import parse_person
from sid.perception.people import Person

FIELDS = ("id", "x", "y", "theta", "orientation_quality")


def test_a_person_is_read_with_the_quality_its_facing_implies() -> None:
    assert parse_person({"id": 4, "x": 1, "y": -2.5, "theta": 3.0}, 0, FIELDS) == Person(4, 1.0, -2.5, 3.0, 1.0)
    assert parse_person({"id": 4, "x": 1, "y": 2, "theta": None}, 0, FIELDS) == Person(4, 1.0, 2.0, None, 0.0)
    read = parse_person({"id": 4, "x": 1, "y": 2, "theta": 0.5, "orientation_quality": 0.25}, 0, FIELDS)
    assert read.orientation_quality == 0.25 and isinstance(read.x, float)


def test_a_whole_float_id_is_that_integer_and_a_fraction_is_refused() -> None:
    read = parse_person({"id": 3.0, "x": 0, "y": 0}, 0, FIELDS)  # pandas writes a float column's 3 as 3.0
    assert read.id == 3 and isinstance(read.id, int)
    for bad in (1.5, 1e300, float("nan")):
        with pytest.raises(ValueError, match="id must be an integer"):
            parse_person({"id": bad, "x": 0, "y": 0}, 0, FIELDS)


def test_a_missing_id_is_the_index_only_where_the_command_says_so() -> None:
    assert parse_person({"x": 0, "y": 0}, 3, FIELDS, id_default=True).id == 3
    with pytest.raises(ValueError, match=r"^people\[3\] is missing 'id'$"):
        parse_person({"x": 0, "y": 0}, 3, FIELDS)


@pytest.mark.parametrize(
    ("data", "fields", "message"),
    [
        ({"id": 1, "x": 0, "y": 0, "orientation_quality": 1}, ("id", "x", "y", "theta"), "unknown field"),
        ({"id": True, "x": 0, "y": 0}, FIELDS, r"people\[0\]: id must be an integer, got true"),
        ({"id": 1, "x": 0, "y": 0, "theta": 90.0}, FIELDS, r"people\[0\] \(id 1\): theta 90 is beyond two turns"),
        ({"id": 1, "x": 0, "y": 0, "orientation_quality": -0.1}, FIELDS, r"must be a number in \[0, 1\], got -0.1"),
        ([1, 2], FIELDS, r"people\[0\] must be an object with id, x, y, theta, orientation_quality"),
    ],
)
def test_bad_people_are_named(data: object, fields: tuple[str, ...], message: str) -> None:
    with pytest.raises(ValueError, match=message):
        parse_person(data, 0, fields)

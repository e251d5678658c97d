"""One error format for bad numbers in parameter records: ``owner: name must be <rule>, got <value>``."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np
import pytest

from sid.checks import YAW_LIMIT_RAD, check_number, check_numbers, check_whole, check_yaw, check_yaws, repeated


@pytest.mark.parametrize(
    ("value", "bounds", "rule"),
    [
        (math.nan, {}, "a finite number"),
        (math.inf, {"unit": "metres"}, "a finite number of metres"),
        (0.0, {"low": 0, "low_open": True, "unit": "metres"}, "a positive number of metres"),
        (-1.0, {"low": 0}, "a finite number >= 0"),
        (2.0, {"high": 1, "high_open": True}, "a finite number < 1"),
        (1.5, {"low": 0, "high": 1}, "a finite number in [0, 1]"),
        (0.5, {"low": 0, "high": 0.5, "low_open": True, "high_open": True}, "a finite number in (0, 0.5)"),
        (-math.inf, {"low": 0, "allow_inf": True}, "a number >= 0 (or inf)"),
        ("north", {}, "a finite number"),
        ("0.1", {}, "a finite number"),  # float() accepts these; they are not numbers
        (b"1", {}, "a finite number"),
        (True, {"low": 0}, "a finite number >= 0"),
        (np.array(0.5), {}, "a finite number"),
    ],
)
def test_out_of_range_values_are_named_with_the_rule(value, bounds, rule):
    with pytest.raises(ValueError) as error:
        check_number("groups", "eps", value, **bounds)
    shown = repr(value) if isinstance(value, (str, bytes, np.ndarray)) else value  # quoted: not to read as a number
    assert str(error.value) == f"groups: eps must be {rule}, got {shown}"


@pytest.mark.parametrize(
    ("value", "bounds"),
    [(0.0, {"low": 0}), (1.0, {"low": 0, "high": 1}), (math.inf, {"low": 0, "allow_inf": True}), (-3, {})],
)
def test_values_within_the_bounds_pass(value, bounds):
    check_number("groups", "eps", value, **bounds)


def test_the_error_type_can_be_chosen():
    class PlanningError(ValueError):
        pass

    with pytest.raises(PlanningError, match="robot_radius"):
        check_number("problem", "robot_radius", -1.0, low=0, error=PlanningError)


def test_check_numbers_reports_the_first_bad_field():
    @dataclass
    class Params:
        a: float = 1.0
        b: float = -2.0
        c: float = -3.0

    check_numbers("params", Params(), ("a",), low=0)
    with pytest.raises(ValueError, match="params: b must be"):
        check_numbers("params", Params(), ("a", "b", "c"), low=0)


# Limits (issue 15): sizes checked before any allocation, raised with one environment variable.
def test_limit_error_names_field_value_limit_and_how_to_raise_it():
    from sid.checks import LimitError, check_limit

    with pytest.raises(LimitError) as error:
        check_limit("lidar.beams", 10**9, "lidar_beams", "beams")
    assert str(error.value) == (
        "lidar.beams: 1,000,000,000 beams is more than the limit of 100,000 beams (lidar_beams; raise it with "
        "SID_LIMITS=lidar_beams=N)"
    )


def test_sid_limits_raises_a_limit_where_an_entry_point_puts_it_in_force(monkeypatch):
    from sid.checks import LimitError, Limits, check_limit, limits, limits_from_environment, use_limits

    monkeypatch.setenv("SID_LIMITS", "people=5000, map_cells=1e8")
    assert limits() == Limits()  # the checks do not read the environment
    with use_limits(limits_from_environment()) as raised:
        assert raised == limits() == Limits(map_cells=100_000_000, people=5000)
        check_limit("people", 4000, "people", "people")  # no error
        # nested: the innermost holds, then the outer again
        with use_limits(Limits(people=3)), pytest.raises(LimitError, match="more than the limit of 3 people"):
            check_limit("people", 4, "people", "people")
        assert limits() == raised
    assert limits() == Limits()


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("peple=5", "unknown limit 'peple'"),
        ("people=0", "people must be a whole number >= 1"),
        ("people=1.5", "whole"),
        ("people=5,people=6", "people is given twice"),  # the last one silently won
    ],
)
def test_a_malformed_sid_limits_is_named(monkeypatch, text, message):
    from sid.checks import limits_from_environment

    monkeypatch.setenv("SID_LIMITS", text)
    with pytest.raises(ValueError, match=rf"\$SID_LIMITS: .*{message}"):
        limits_from_environment()


@pytest.mark.parametrize("value", [0, 10, 2.5, True, float("nan"), float("inf"), "3", None])
def test_whole_numbers_are_checked_with_one_message(value: object) -> None:
    # inf, NaN and strings included: int(inf) raises OverflowError, int("x") a conversion error of its own.
    with pytest.raises(ValueError, match=re.escape(f"owner: count must be a whole number from 1 to 9, got {value!r}")):
        check_whole("owner", "count", value, low=1, high=9)


def test_a_whole_number_comes_back_as_an_int() -> None:
    assert check_whole("owner", "count", 4.0, low=1) == 4 and isinstance(check_whole("owner", "count", 4.0), int)
    assert check_whole("owner", "count", np.int64(7), high=7) == 7
    with pytest.raises(KeyError, match="owner: count must be a whole number >= 0"):
        check_whole("owner", "count", -1, low=0, error=KeyError)


def test_repeated_names_the_first_item_given_twice_in_order() -> None:
    assert repeated(["grid", "bitstar", "rrtstar"]) is None and repeated([]) is None
    assert repeated(["S2", "S1", "S2", "S1"]) == "S2"
    assert repeated(["a", "b", "b", "a"]) == "a"  # the first item in order that appears again, not the first repeat


def test_a_string_is_quoted_so_that_it_does_not_read_as_a_number() -> None:
    with pytest.raises(ValueError, match=r"^groups: radius_max must be a finite number of metres, got '0.8'$"):
        check_number("groups", "radius_max", "0.8", unit="metres")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"got nan$"):
        check_number("groups", "radius_max", math.nan, unit="metres")


def test_yaws_of_a_record_are_numbers_within_two_turns() -> None:
    from sid.perception.mount import CameraMount

    check_yaws("mount", CameraMount(0.9, yaw=-2 * math.pi), ("yaw",))
    with pytest.raises(ValueError, match=r"^camera mount: yaw 90 is beyond two turns \(4 pi\): radians expected"):
        CameraMount(0.9, yaw=90.0)
    with pytest.raises(ValueError, match=r"^camera mount: yaw must be a finite number of radians, got '1'$"):
        CameraMount(0.9, yaw="1")  # type: ignore[arg-type]


def test_a_yaw_beyond_two_turns_is_refused_as_degrees() -> None:
    check_yaw("people[0]", "theta", -YAW_LIMIT_RAD)  # an unwrapped yaw
    with pytest.raises(ValueError, match=r"^people\[0\]: theta 90 is beyond two turns \(4 pi\): radians expected"):
        check_yaw("people[0]", "theta", 90.0)

"""The pipeline's JSON record (``sid.perception.pipeline.FrameResult.to_json``)."""

from __future__ import annotations

import numpy as np

from sid.perception.people import Person
from sid.perception.pipeline import FrameResult


def _record(keypoints: np.ndarray) -> dict:
    person = Person(3, 1.23456, -0.5, 0.25, 0.9, keypoints)
    return FrameResult(0, 0.0, [], [person], []).to_json()["people"][0]


def test_keypoints_are_rounded_to_a_tenth_of_a_millimetre_and_missing_ones_are_null() -> None:
    keypoints = np.random.default_rng(0).normal(0.0, 3.0, (17, 3))
    keypoints[[2, 9]] = np.nan
    keypoints[5, 1] = np.nan  # one missing coordinate makes the whole keypoint missing
    record = _record(keypoints)
    assert record["x"] == 1.2346 and record["id"] == 3
    rows = record["keypoints"]
    assert [k for k, row in enumerate(rows) if row is None] == [2, 5, 9]
    expected = [[round(float(v), 4) for v in k] for k in keypoints]  # Python's round: the reference
    assert all(row == expected[k] for k, row in enumerate(rows) if row is not None)
    assert all(type(v) is float for row in rows if row is not None for v in row)  # plain JSON numbers


def test_a_person_without_keypoints_has_null() -> None:
    person = Person(1, 0.0, 0.0, None, 0.0)
    assert FrameResult(0, 0.0, [], [person], []).to_json()["people"][0]["keypoints"] is None

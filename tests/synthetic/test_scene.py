"""Scene records and scene files: a facing in degrees is refused, as in scenario files."""

from __future__ import annotations

import math

import pytest

from sid.synthetic.scene import Scene, ScenePerson


def test_a_yaw_beyond_two_turns_is_refused_as_degrees() -> None:
    with pytest.raises(ValueError, match=r"scene person 3: theta 90 is beyond two turns \(4 pi\): radians expected"):
        ScenePerson(3, 2.0, 0.0, 90.0)
    data = {"people": [{"x": 2.0, "y": 0.0, "theta": 0.0}, {"x": 2.0, "y": 1.0, "yaw": -180}]}
    with pytest.raises(ValueError, match=r"people\[1\]: scene person 1: theta -180 is beyond two turns"):
        Scene.from_dict(data)
    assert ScenePerson(0, 2.0, 0.0, -math.pi).theta == -math.pi  # radians, even a turn or so off, stay accepted
    assert ScenePerson(0, 2.0, 0.0, 3 * math.pi).theta == 3 * math.pi

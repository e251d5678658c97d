"""The paper's layouts S1-S5 and scene files."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import yaml

from sid.synthetic.layouts import LAYOUTS, VARIATIONS, Formation, layout, variations
from sid.synthetic.scene import Scene
from sid.synthetic.sequence import SyntheticSequence, load_scene_file
from tests.conftest import REPO_ROOT


def _xy(scene: Scene) -> np.ndarray:
    return np.array([[p.x, p.y] for p in scene.people])


@pytest.mark.parametrize("name", list(LAYOUTS))
def test_everyone_faces_the_formation_centre_in_one_group(name: str) -> None:
    scene = layout(name)
    spec = LAYOUTS[name]
    assert len(scene.people) == len(spec.angles_deg)
    assert scene.groups == (tuple(range(len(scene.people))),)
    centre = np.array([spec.centre_distance, 0.0])
    for person in scene.people:
        towards = centre - np.array([person.x, person.y])
        assert np.linalg.norm(towards) == pytest.approx(spec.radius)
        facing = np.array([np.cos(person.theta), np.sin(person.theta)])
        assert facing @ towards / np.linalg.norm(towards) == pytest.approx(1.0)


def test_layout_shapes_match_the_paper() -> None:
    s1 = _xy(layout("S1"))
    assert np.linalg.norm(s1[0] - s1[1]) == pytest.approx(0.8)
    s3 = _xy(layout("S3"))
    sides = [np.linalg.norm(s3[i] - s3[(i + 1) % 3]) for i in range(3)]
    np.testing.assert_allclose(sides, 1.2)
    for name in ("S2", "S4"):  # semicircles open towards the camera: everyone behind the centre, facing it
        scene = layout(name)
        assert all(p.x >= LAYOUTS[name].centre_distance for p in scene.people)
        assert all(np.cos(p.theta) < 0 for p in scene.people)


@pytest.mark.parametrize("name", list(LAYOUTS))
def test_all_variations_stand_1_5_to_3_m_in_front_of_the_camera(name: str) -> None:
    scenes = variations(name)
    assert len(scenes) == len(VARIATIONS)
    for scene in scenes:
        x = _xy(scene)[:, 0]
        assert x.min() >= 1.5 and x.max() <= 3.05
    assert len({tuple(map(tuple, _xy(s).round(6))) for s in scenes}) == len(VARIATIONS)  # all different


def test_variations_apply_to_the_callers_formation() -> None:
    """Nearer/further move from the caller's centre distance, turns add to the caller's rotation, the jitter
    variations' seeds add to the caller's; the options the jitter variations set are refused."""
    scenes = variations("S3", centre_distance=3.0, rotation=0.3, seed=5)
    centres = [float(np.mean(_xy(s)[:, 0])) for s in scenes[:5]]  # the triangle's centroid is its centre
    np.testing.assert_allclose(centres, [3.0, 3.0, 3.0, 2.85, 3.15], atol=1e-9)
    turn = np.radians(LAYOUTS["S3"].turn_deg)
    for scene, rotation in zip(scenes[:3], (0.3, 0.3 - turn, 0.3 + turn), strict=True):
        assert scene == layout("S3", centre_distance=3.0, rotation=rotation)
    assert scenes[5] == layout(
        "S3", centre_distance=3.0, rotation=0.3, jitter_xy=0.05, jitter_theta=np.radians(5.0), seed=6
    )
    assert scenes[5] != variations("S3", centre_distance=3.0, rotation=0.3)[5]
    assert variations("S3") == variations("S3", formation=Formation())
    with pytest.raises(ValueError, match="variations of S3: jitter_xy are set by the jitter variations"):
        variations("S3", jitter_xy=0.1)


def test_focus_offset_opens_the_group_towards_the_camera() -> None:
    scene = layout("S1", focus_offset=0.4)
    for person in scene.people:  # both face (1.8, 0): 45 deg from each other, towards the camera
        assert np.degrees(person.theta) == pytest.approx(np.sign(person.theta) * 135.0)
    with pytest.raises(ValueError, match="stands on the point"):
        layout("S1", rotation=np.pi / 2, focus_offset=0.4)  # person 0 at (1.8, 0), the focus


def test_jitter_is_seeded() -> None:
    first = layout("S4", jitter_xy=0.05, jitter_theta=0.1, seed=3)
    assert first == layout("S4", jitter_xy=0.05, jitter_theta=0.1, seed=3)
    assert first != layout("S4", jitter_xy=0.05, jitter_theta=0.1, seed=4)
    assert layout("s4") == layout("S4")


def test_rotation_turns_the_formation_about_its_centre() -> None:
    turned = layout("S3", rotation=np.pi / 2)
    xy = _xy(turned)
    np.testing.assert_allclose(xy[0], [2.2, 1.2 / np.sqrt(3)], atol=1e-12)


def test_bad_layout_requests_are_rejected() -> None:
    with pytest.raises(ValueError, match="unknown layout"):
        layout("S9")
    with pytest.raises(ValueError, match="radius"):
        layout("S1", radius=-1.0)
    with pytest.raises(ValueError, match="jitter_xy"):
        layout("S1", jitter_xy=-0.1)
    with pytest.raises(ValueError, match="apart"):
        layout("S5", radius=0.1)


def test_scene_files_round_trip(tmp_path: Path) -> None:
    scene = layout("S2", height=1.8)
    json_path = tmp_path / "scene.json"
    json_path.write_text(json.dumps(scene.to_dict()))
    assert Scene.from_file(json_path) == scene
    yaml_path = tmp_path / "scene.yaml"
    yaml_path.write_text(yaml.safe_dump(scene.to_dict()))
    assert Scene.from_file(yaml_path) == scene


def test_yaw_defaults(tmp_path: Path) -> None:
    path = tmp_path / "people.yaml"
    path.write_text("people:\n  - {x: 2.0, y: 0.5, yaw: 3.0}\n  - {x: 2.0, y: -0.5, yaw: -3.0}\n")
    scene = Scene.from_file(path)
    assert [p.id for p in scene.people] == [0, 1] and scene.people[0].theta == 3.0
    assert scene.groups == () and scene.mount.height == 0.9 and scene.name == "people"


def test_scenario_files_are_sequences_seen_from_the_robot(tmp_path: Path) -> None:
    scenario = {
        "name": "turned",
        "map": {"resolution": 0.1, "origin": [-5.0, -5.0], "size": [10.0, 10.0]},
        "people": [{"id": 7, "x": 1.0, "y": 3.0, "theta": 0.0}, {"id": 8, "x": 1.0, "y": 4.0, "theta": np.pi}],
        "robot": {"start": [1.0, 1.0, np.pi / 2], "goal": [1.0, -1.0, 0.0]},
    }
    path = tmp_path / "scenario.json"
    path.write_text(json.dumps(scenario))
    with pytest.raises(ValueError, match="costmap scenario file"):
        Scene.from_file(path)
    sequence = load_scene_file(path)
    assert isinstance(sequence, SyntheticSequence) and sequence.name == "turned" and sequence.duration == 0
    moment = sequence.at(0.0)
    # The robot at (1, 1) looks along +y: person 7 is 2 m straight ahead, facing the robot's right (-pi/2).
    seen = moment.seen_people[0]
    assert (seen.id, seen.x, seen.y) == pytest.approx((7, 2.0, 0.0))
    assert seen.theta == pytest.approx(-np.pi / 2)
    assert (moment.people[0].x, moment.people[0].y, moment.people[0].theta) == (1.0, 3.0, 0.0)
    scenario["people"][0].pop("theta")
    path.write_text(json.dumps(scenario))
    with pytest.raises(ValueError, match=r"people \[7\] have no facing direction"):
        load_scene_file(path)
    examples = REPO_ROOT / "examples" / "conversation.json"
    if examples.is_file():  # the repository's example scenario renders as is
        example = load_scene_file(examples)
        assert isinstance(example, SyntheticSequence) and len(example.people) == 4


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("{not json", "not valid JSON"),
        ('{"people": []}', "non-empty"),
        ('{"people": [{"x": 1, "y": 0}]}', "theta"),
        ('{"people": [{"x": "a", "y": 0, "theta": 0}]}', "people\\[0\\]"),
        ('{"people": [{"x": 2, "y": 0, "theta": 0, "height": 9}]}', "standing person"),
        ('{"people": [{"x": 2, "y": 0, "theta": 0}], "groups": [[0, 7]]}', "unknown people"),
        ('{"people": [{"x": 6, "y": 0, "theta": 0}]}', "wall"),
    ],
)
def test_malformed_scene_files_name_the_problem(tmp_path: Path, text: str, message: str) -> None:
    path = tmp_path / "bad.json"
    path.write_text(text)
    with pytest.raises(ValueError, match=message):
        Scene.from_file(path)
    with pytest.raises(ValueError, match="cannot read"):
        Scene.from_file(tmp_path / "missing.json")

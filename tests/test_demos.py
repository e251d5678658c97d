"""Every script in demos/ runs to the end with no arguments and does what its docstring promises: the files it
writes are readable pictures, and its key lines are printed. Lines are read loosely (names, counts and orderings
such as "with the social layer, no intrusion"), never exact measurements or timings."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import cv2
import pytest

from tests.conftest import REPO_ROOT, SHARED

DEMOS = sorted((REPO_ROOT / "demos").glob("*.py"))


def _picture(path: Path) -> None:
    image = cv2.imread(str(path))
    assert image is not None and image.size > 0, f"{path} is not a readable picture"


def _numbers(pattern: str, text: str) -> tuple[float, ...]:
    match = re.search(pattern, text, re.MULTILINE)
    assert match, f"no line matching {pattern!r} in:\n{text}"
    return tuple(float(group) for group in match.groups())


def _written(prefix: str, text: str, folder: Path) -> Path:
    """The file named after ``prefix`` on a printed line; it must lie in the test's folder (cwd and TMPDIR)."""
    (name,) = re.findall(rf"^{prefix}(\S+)", text, re.MULTILINE)
    path = Path(name)
    assert folder in path.parents, f"{path} is outside the test's folder {folder}"
    return path


def align_depth(out: str, cwd: Path) -> None:
    assert "aligned 848x480 depth to 1280x720 colour" in out
    assert out.count("sparse == dense: True") == 2  # both people: sparse look-up agrees with the aligned image
    for person, metres in (("A", 1.8), ("B", 2.6)):
        (median,) = _numbers(rf"^person {person} .*17/17 keypoints with depth, median ([\d.]+) m", out)
        assert median == pytest.approx(metres, abs=0.05)


def detect_groups(out: str, cwd: Path) -> None:
    found = [{int(m) for m in members.split(",")} for members in re.findall(r"^group \[([\d, ]+)\]", out, re.M)]
    assert sorted(found, key=min) == [{1, 2}, {3, 4, 5}]  # the pair and the trio; the passer-by joins neither


def end_to_end(out: str, cwd: Path) -> None:
    assert len(re.findall(r"^person \d+: x ", out, re.M)) == 3
    assert re.search(r"^group \[0, 1, 2\]: interest point", out, re.M)
    length, inside = _numbers(r"^path: ([\d.]+) m, ([\d.]+) m inside group zones", out)
    assert length > 4.5 and inside == 0.0  # to a goal 4.5 m ahead, around the group


def plan_around_group(out: str, cwd: Path) -> None:
    assert re.search(r"groups found: \[\(1, 2, 3\)\]", out)
    row = r": ([\d.]+) m, ([\d.]+) m inside the group zone, closest person ([\d.]+) m"
    lidar = _numbers("^map \\+ LiDAR *" + row, out)
    social = _numbers("^with social layer *" + row, out)
    assert lidar[1] > 0.5 and social[1] == 0.0  # through the conversation without the layer, around it with it
    assert social[2] > lidar[2] and social[0] > lidar[0]  # farther from people, for a longer path
    _picture(cwd / "plan_around_group.png")


def pose_on_image(out: str, cwd: Path) -> None:
    if not (SHARED / "models" / "yolo11n-pose-256.onnx").is_file():
        assert "not found" in out  # the documented stop without ../shared
        return
    (people,) = _numbers(r"^yolo11n-pose-256\.onnx: contract yolo_pose, \d+ threads, (\d+) people", out)
    assert people == 5 and len(re.findall(r"^  person \d+: score", out, re.M)) == 5
    _picture(_written("overlay written to ", out, cwd))


def social_costmap(out: str, cwd: Path) -> None:
    assert re.search(r"^group \(1, 2, 3\): interaction zone", out, re.M)
    (without,) = _numbers(r"without recognition: o-space centre cost +(\d+)", out)
    (with_layer,) = _numbers(r"with the social layer: o-space centre cost +(\d+)", out)
    assert with_layer > without
    _picture(_written("picture: ", out, cwd))


def synthetic_scene(out: str, cwd: Path) -> None:
    assert re.search(r"^S3: .*; 8 frames", out, re.M)
    assert re.search(r"^group \(0, 1, 2\): interest point", out, re.M)
    for name in ("color.png", "depth.png"):
        _picture(cwd / "synthetic_scene" / name)


def track_people(out: str, cwd: Path) -> None:
    assert re.search(r"^t = +\d+\.\d s \(map\)", out, re.M)  # positions in the map frame: the frames carry a pose
    walking = re.findall(r"^  group (\d+): walking, members \[(\d+), (\d+)\]", out, re.M)
    assert {g for g, *_ in walking} and len({g for g, *_ in walking}) == 2  # the pair in file, the pair side by side
    assert "conversation" not in out  # walkers are never a conversation
    tracks = {int(i) for i in re.findall(r"^  track (\d+):", out, re.M)}
    assert len(tracks) == 4  # four people, four track ids: none lost and renumbered


PROMISES: dict[str, Callable[[str, Path], None]] = {
    check.__name__: check
    for check in (
        align_depth,
        detect_groups,
        end_to_end,
        plan_around_group,
        pose_on_image,
        social_costmap,
        synthetic_scene,
        track_people,
    )
}


@pytest.mark.parametrize("script", DEMOS, ids=[d.stem for d in DEMOS])
def test_demo_runs_and_keeps_its_promise(script, tmp_path):
    assert script.stem in PROMISES, f"demos/{script.name} has no promise checked here: add one to PROMISES"
    env = {**os.environ, "PYTHONPATH": str(REPO_ROOT), "MPLBACKEND": "Agg", "TMPDIR": str(tmp_path)}
    result = subprocess.run(
        [sys.executable, str(script)], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300
    )
    assert result.returncode == 0, f"{script.name} failed:\n{result.stdout[-2000:]}\n{result.stderr[-4000:]}"
    PROMISES[script.stem](result.stdout, tmp_path)

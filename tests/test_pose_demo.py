"""The pose demo end to end on a stand-in model, and its clear stop when no model is there."""

from __future__ import annotations

import re
import runpy
import tempfile

import cv2
import numpy as np

from sid.perception.keypoints import KP
from tests.conftest import REPO_ROOT
from tests.pose_models import build_multipose_model

DEMO = REPO_ROOT / "demos" / "pose_on_image.py"


def stand_in_person() -> np.ndarray:
    """MultiPose output rows (6, 56): one stick figure facing the camera, (dy, dx) of each keypoint from the red
    marker on its nose (normalised to the model input), score 0.8, and a box around it with score 0.9."""
    figure = {"nose": (0, 0), "eye": (-0.02, 0.012), "ear": (-0.01, 0.025), "shoulder": (0.1, 0.06)}
    figure |= {"elbow": (0.25, 0.08), "wrist": (0.38, 0.08), "hip": (0.4, 0.04), "knee": (0.57, 0.045)}
    figure |= {"ankle": (0.74, 0.045)}
    offsets = np.array([figure[name.split("_")[-1]] for name in KP], dtype=float)
    offsets[[i for name, i in KP.items() if name.startswith("right")], 1] *= -1  # its left on the image's right
    person = np.zeros((6, 56))
    person[0, :51] = np.column_stack([offsets, np.full(17, 0.8)]).ravel()
    person[0, 51:] = [-0.06, -0.11, 0.78, 0.11, 0.9]  # box (ymin, xmin, ymax, xmax), score
    return person


def test_pose_demo_runs_a_model_on_an_image(tmp_path, monkeypatch, capsys):
    model = build_multipose_model(tmp_path / "stand_in_multipose.onnx", stand_in_person(), marker=True)
    image = np.full((480, 640, 3), 120, np.uint8)
    cv2.circle(image, (400, 100), 6, (0, 0, 255), cv2.FILLED)  # BGR red: the marker the stand-in model finds
    cv2.imwrite(str(tmp_path / "image.png"), image)
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))

    assert runpy.run_path(str(DEMO))["main"](model, tmp_path / "image.png") == 0
    out = capsys.readouterr().out
    assert "contract movenet_multipose" in out and "1 people" in out
    u0, v0, u1, v1 = map(int, re.search(r"box \(u, v\) \[(\d+), (\d+), (\d+), (\d+)\]", out).groups())
    assert u0 < 400 < u1 and v0 < 100 < v1  # the figure stands around the red dot, in image pixels
    assert len(list(tmp_path.glob("sid_pose_demo_*/pose_overlay.png"))) == 1


def test_pose_demo_without_a_model_says_what_to_pass(tmp_path, capsys):
    assert runpy.run_path(str(DEMO))["main"](tmp_path / "none.onnx", tmp_path / "none.png") == 1
    out = capsys.readouterr().out
    assert "not found" in out and "none.onnx" in out and "docs/models.md" in out

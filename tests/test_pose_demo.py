"""The pose demo's fallback path: without ../shared it builds a stand-in MultiPose model and still runs."""

from __future__ import annotations

import runpy
import tempfile

from tests.conftest import REPO_ROOT


def test_pose_demo_runs_without_shared_material(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    demo = runpy.run_path(str(REPO_ROOT / "demos" / "pose_on_image.py"))
    demo["main"](tmp_path / "no_shared_here")
    out = capsys.readouterr().out
    assert "stand-in model with the MoveNet MultiPose signature" in out
    assert "contract movenet_multipose" in out and "1 people" in out
    assert len(list(tmp_path.glob("sid_pose_demo_*/pose_overlay.png"))) == 1

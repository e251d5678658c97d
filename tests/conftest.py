"""Shared test fixtures: where the optional real data lives, and how tests skip without it."""

from __future__ import annotations

import os
from pathlib import Path
from types import ModuleType

import pytest
from hypothesis import settings

# Property tests have no per-example deadline: a deadline is a wall-clock limit, and on a shared or busy machine an
# example that takes 300 ms instead of 200 fails the suite for nothing (speed is measured by `sid bench`). In CI
# (CI=true, as .ci/run is run) they also draw the same examples on every run and every Python version;
# `HYPOTHESIS_PROFILE=ci` selects the same locally.
settings.register_profile("local", deadline=None)
settings.register_profile("ci", derandomize=True, deadline=None, database=None, print_blob=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE") or ("ci" if os.environ.get("CI") else "local"))

REPO_ROOT = Path(__file__).resolve().parents[1]
SHARED = REPO_ROOT.parent / "shared"


def shared_path(*parts: str) -> Path:
    """A path under ../shared, or skip the calling test with the reason when it is absent."""
    path = SHARED.joinpath(*parts)
    if not path.exists():
        pytest.skip(f"real data {path} is absent (../shared is not checked out next to the repo)")
    return path


def realsense() -> ModuleType:
    """pyrealsense2, or skip the calling test (or, called at import time, the whole module) saying why it cannot
    load: it is not installed, or the system library libusb-1.0-0 is missing (`sudo apt-get install libusb-1.0-0`)."""
    try:
        import pyrealsense2
    except ImportError as exc:
        pytest.skip(f"pyrealsense2 cannot be loaded ({exc}); it needs libusb-1.0-0", allow_module_level=True)
    return pyrealsense2


@pytest.fixture
def shared() -> type:
    """Gives tests `shared.path(...)` that skips when ../shared is absent."""

    class _Shared:
        root = SHARED
        path = staticmethod(shared_path)

    return _Shared


@pytest.fixture
def legend(monkeypatch: pytest.MonkeyPatch) -> list[list[str]]:
    """The legend rows of every top view (``costmap.render.render_costmap``) drawn in the test, by name: a spy on the
    panel that draws them."""
    import costmap.render as render

    seen: list[list[str]] = []
    panel = render._panel

    def spy(img, spec, scale, costs, rows):  # type: ignore[no-untyped-def]
        seen.append([name for name, _ in rows])
        panel(img, spec, scale, costs, rows)

    monkeypatch.setattr(render, "_panel", spy)
    return seen

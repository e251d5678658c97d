"""Shared test fixtures: where the optional real data lives, and how tests skip without it."""

from __future__ import annotations

from pathlib import Path

import pytest

REPO_ROOT = Path(__file__).resolve().parents[1]
SHARED = REPO_ROOT.parent / "shared"


def shared_path(*parts: str) -> Path:
    """A path under ../shared, or skip the calling test with the reason when it is absent."""
    path = SHARED.joinpath(*parts)
    if not path.exists():
        pytest.skip(f"real data {path} is absent (../shared is not checked out next to the repo)")
    return path


@pytest.fixture
def shared() -> type:
    """Gives tests `shared.path(...)` that skips when ../shared is absent."""

    class _Shared:
        root = SHARED
        path = staticmethod(shared_path)

    return _Shared

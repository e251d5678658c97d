"""What sid is installed as: its distribution name on the package index, the install command of an extra, and the
error raised when an optional dependency is missing (its message gives that command)."""

from __future__ import annotations

from sid.errors import SidError

__all__ = ["DISTRIBUTION", "MissingDependencyError", "install_hint"]

DISTRIBUTION = "sid-social"
"""The name sid is installed under (``pip install sid-social``): the package index's ``sid`` is another project.
The import package and the ``sid`` command keep the name ``sid``."""


def install_hint(extra: str) -> str:
    """The command that installs sid with its optional ``extra`` (pyproject.toml), e.g.
    ``pip install 'sid-social[ros]'``."""
    return f"pip install '{DISTRIBUTION}[{extra}]'"


class MissingDependencyError(SidError, RuntimeError):
    """An optional package a command needs is not installed; the message names it and gives ``install_hint``."""

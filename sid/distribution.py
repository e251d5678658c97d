"""What sid is installed as: its distribution name on the package index, and the install command of an extra that
every message about a missing optional dependency gives."""

from __future__ import annotations

__all__ = ["DISTRIBUTION", "install_hint"]

DISTRIBUTION = "sid-social"
"""The name sid is installed under (``pip install sid-social``): the package index's ``sid`` is another project.
The import package and the ``sid`` command keep the name ``sid``."""


def install_hint(extra: str) -> str:
    """The command that installs sid with its optional ``extra`` (pyproject.toml), e.g.
    ``pip install 'sid-social[ros]'``."""
    return f"pip install '{DISTRIBUTION}[{extra}]'"

"""The one base of the errors sid raises on purpose."""

from __future__ import annotations

__all__ = ["SidError"]


class SidError(Exception):
    """Base of every error sid raises on purpose: bad input, a missing dependency, an impossible task. Each also
    derives from the built-in error it stands for (``ValueError``, ``RuntimeError``), so ``except ValueError`` still
    catches a bad scenario, and ``except SidError`` catches everything sid means to say."""

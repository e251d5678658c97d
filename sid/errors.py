"""The one base of the errors sid raises on purpose."""

from __future__ import annotations

__all__ = ["InputError", "InputTypeError", "SidError"]


class SidError(Exception):
    """Base of every error sid raises on purpose: bad input, a missing dependency, an impossible task. Each also
    derives from the built-in error it stands for (``ValueError``, ``RuntimeError``), so ``except ValueError`` still
    catches a bad scenario, and ``except SidError`` catches everything sid means to say."""


class InputError(SidError, ValueError):
    """A value, array, record or file sid cannot use; the message names it and says what is expected."""


class InputTypeError(SidError, TypeError):
    """An argument of a type sid does not take (a tuple for a record, a list for an array); the message names it."""

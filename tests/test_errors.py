"""One error base: every exception class sid, costmap and planner define derives from ``sid.errors.SidError``, and
none of them raises a bare built-in ValueError or TypeError."""

from __future__ import annotations

import ast
import importlib
import inspect
import pkgutil

import pytest

import costmap
import planner
import sid
from sid.errors import SidError
from tests.conftest import REPO_ROOT


def _modules() -> list[str]:
    names = []
    for package in (sid, costmap, planner):
        names.append(package.__name__)
        names += [m.name for m in pkgutil.walk_packages(package.__path__, f"{package.__name__}.")]
    return sorted(names)


def _defined_errors() -> list[type[Exception]]:
    found = []
    for name in _modules():
        if name.endswith("__main__"):
            continue
        try:
            module = importlib.import_module(name)
        except ImportError as exc:  # an optional extra (ROS 2, OpenVINO, Ray) that is not installed
            if exc.name and exc.name.split(".")[0] in {"sid", "costmap", "planner"}:
                raise
            continue
        for _, value in inspect.getmembers(module, inspect.isclass):
            is_error = issubclass(value, Exception) and not issubclass(value, Warning)  # not signals (Terminated)
            if is_error and value.__module__ == name:
                found.append(value)
    return found


ERRORS = _defined_errors()


def test_the_packages_define_errors() -> None:
    names = {e.__name__ for e in ERRORS}
    assert {"ScenarioError", "SourceError", "PlanningError", "MapFileError", "LimitError"} <= names


@pytest.mark.parametrize("error", ERRORS, ids=lambda e: f"{e.__module__}.{e.__name__}")
def test_every_error_derives_from_the_one_base(error: type[Exception]) -> None:
    assert issubclass(error, SidError)


# Deliberately without a built-in base: the base itself; stdout failing is not one of a command's own files (not an
# OSError, sid.cli.common); a recorded frame missing a stream is turned into a FrameReadError inside the source.
_WITHOUT_BUILTIN = {"SidError", "StandardOutputError", "IncompleteFrame"}


@pytest.mark.parametrize("error", ERRORS, ids=lambda e: f"{e.__module__}.{e.__name__}")
def test_every_error_also_derives_from_the_builtin_error_it_stands_for(error: type[Exception]) -> None:
    # The README's promise: `except ValueError` still catches bad input (a pose model file that cannot be used did not).
    builtin = [b for b in error.__mro__ if b.__module__ == "builtins" and b not in (Exception, BaseException, object)]
    assert bool(builtin) != (error.__name__ in _WITHOUT_BUILTIN)


def _bare_raises() -> list[str]:
    """``path:line`` of each ``raise ValueError(...)`` / ``raise TypeError(...)`` in the three packages."""
    found = []
    for package in ("sid", "costmap", "planner"):
        for path in sorted((REPO_ROOT / package).rglob("*.py")):
            for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
                raised = node.exc.func if isinstance(node, ast.Raise) and isinstance(node.exc, ast.Call) else None
                if isinstance(raised, ast.Name) and raised.id in {"ValueError", "TypeError"}:
                    found.append(f"{path.relative_to(REPO_ROOT)}:{node.lineno}")
    return found


def test_no_input_check_raises_a_bare_builtin_error() -> None:
    # The README's promise, ``except SidError`` catches every error sid means to say: 13 input checks (colour and
    # depth dtypes, duplicate ids, GroupParams, CameraMount, ...) raised plain ValueError or TypeError.
    assert _bare_raises() == []
    with pytest.raises(SidError, match="groups: eps must be a positive number"):
        sid.GroupParams(eps=-1.0)

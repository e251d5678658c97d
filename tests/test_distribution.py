"""sid is installed as ``sid-social`` (the package index's ``sid`` is another project): pyproject.toml declares that
name, and every install command the code prints or the documents give names it, never ``sid`` or ``sid[extra]``."""

from __future__ import annotations

import re
import sys
from pathlib import Path

import pytest

from sid.distribution import DISTRIBUTION, MissingDependencyError, install_hint
from tests.conftest import REPO_ROOT

PYPROJECT = (REPO_ROOT / "pyproject.toml").read_text()
# Code and documents: the packages, their data files, the demos, README, docs/, pyproject.toml and CI.
SOURCES = sorted(
    {
        *(p for package in ("sid", "costmap", "planner", "demos") for p in (REPO_ROOT / package).rglob("*.py")),
        *(REPO_ROOT / "sid").rglob("*.yaml"),
        *(REPO_ROOT / "docs").rglob("*.md"),
        REPO_ROOT / "README.md",
        REPO_ROOT / "pyproject.toml",
        REPO_ROOT / ".ci" / "run",
    }
)
PIP_INSTALL = re.compile(r"pip3? install((?:[ \t]+[^\s`;&|)\",]+)+)")


def _extras() -> set[str]:
    """The extras pyproject.toml's [project.optional-dependencies] declares."""
    section = PYPROJECT.split("[project.optional-dependencies]", 1)[1].split("\n[", 1)[0]
    return set(re.findall(r"^([\w-]+) = \[", section, flags=re.MULTILINE))


def _requirements(text: str) -> list[str]:
    """The requirements of every ``pip install`` command in ``text`` (options dropped, quotes stripped)."""
    found = []
    for match in PIP_INSTALL.finditer(text):
        for token in match.group(1).split():
            if token.startswith("#"):  # a shell comment
                break
            if not token.startswith("-"):
                found.append(token.strip("'"))
    return found


def test_pyproject_declares_the_distribution_name() -> None:
    assert re.search(r'^name = "([^"]+)"', PYPROJECT, flags=re.MULTILINE).group(1) == DISTRIBUTION
    assert install_hint("ros") == f"pip install '{DISTRIBUTION}[ros]'"


def test_the_requirement_reader_sees_what_a_hint_names() -> None:
    text = "install with `pip install 'sid[ros]'`; or pip install -q -e '.[test]' && pip install sid motmetrics # sid"
    assert _requirements(text) == ["sid[ros]", ".[test]", "sid", "motmetrics"]


@pytest.mark.parametrize("path", SOURCES, ids=lambda p: str(p.relative_to(REPO_ROOT)))
def test_every_install_command_names_the_distribution(path: Path) -> None:
    text = path.read_text()
    for requirement in _requirements(text):
        name = re.match(r"[\w.{}-]*", requirement).group(0)
        assert name != "sid", f"{path}: `pip install {requirement}` installs the package index's other 'sid'"
        if "[" in requirement:  # an extra of ours: from the index by our name, or from the checkout
            assert name in (DISTRIBUTION, ".", "{DISTRIBUTION}"), f"{path}: pip install {requirement}"
    for extra in re.findall(r"install_hint\(['\"]([^'\"]+)['\"]\)", text):
        assert extra in _extras(), f"{path}: install_hint({extra!r}) names no extra of pyproject.toml"
    for extra in re.findall(rf"{re.escape(DISTRIBUTION)}\[([\w,-]+)\]", text):
        assert set(extra.split(",")) <= _extras(), f"{path}: {DISTRIBUTION}[{extra}] names no extra of pyproject.toml"


def test_the_printed_hints_give_the_install_command(monkeypatch: pytest.MonkeyPatch) -> None:
    """Each message about a missing optional dependency, raised with the dependency hidden."""
    from sid.cli.ros import INSTALL_HINT
    from sid.experiments import crowd, synthetic_tracking
    from sid.experiments.simulate.sweep import _on_ray
    from sid.perception.pose.session import OPENVINO_MISSING

    assert install_hint("ros") in INSTALL_HINT and install_hint("openvino") in OPENVINO_MISSING
    monkeypatch.setattr(synthetic_tracking.importlib.util, "find_spec", lambda name: None)
    with pytest.raises(MissingDependencyError, match=re.escape(install_hint("eval"))):
        crowd.require_motmetrics()
    monkeypatch.setitem(sys.modules, "ray", None)  # import ray now raises ImportError
    with pytest.raises(MissingDependencyError, match=re.escape(install_hint("cluster"))):
        _on_ray([], "local", None)
    from sid.perception.pose.quantize import quantize_model

    monkeypatch.setitem(sys.modules, "onnx", None)
    with pytest.raises(MissingDependencyError, match=re.escape(install_hint("quantize"))):
        quantize_model("model.onnx", "int8.onnx", [])

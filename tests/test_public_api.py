"""``import sid``: the public names resolve to their modules' objects, and importing sid alone stays cheap."""

from __future__ import annotations

import ast
import importlib
import subprocess
import sys
from pathlib import Path

import pytest

import sid
from tests.conftest import REPO_ROOT


@pytest.mark.parametrize("name", sid.__all__)
def test_public_name_is_the_object_of_its_module(name):
    module = importlib.import_module(sid._EXPORTS[name])
    assert getattr(sid, name) is getattr(module, name)
    assert name in dir(sid)


def test_unknown_names_raise_attribute_error():
    with pytest.raises(AttributeError, match="no attribute 'Nope'"):
        _ = sid.Nope


def test_a_type_checker_sees_the_public_names_and_refuses_a_misspelt_one(tmp_path, monkeypatch):
    """The lazy loader (module ``__getattr__``) is hidden from type checkers: else every ``sid.X`` would be Any."""
    api = pytest.importorskip("mypy.api", reason="mypy (the test extra) is not installed")
    user = tmp_path / "user.py"
    user.write_text("import sid\n\nsid.Pipeline\nsid.Pipline\nreveal_type(sid.detect_groups)\n")
    monkeypatch.setenv("MYPYPATH", str(REPO_ROOT))  # an editable install's import hook is invisible to mypy
    report, _, _ = api.run(["--follow-imports=silent", "--no-incremental", "--python-version=3.10", str(user)])
    lines = report.splitlines()
    assert [line.split(":", 1)[1] for line in lines if ": error:" in line] == [
        '4: error: Module has no attribute "Pipline"  [attr-defined]'
    ]
    assert any("def (people:" in line for line in lines), report


def test_version_is_a_plain_string():
    assert isinstance(sid.__version__, str) and sid.__version__.count(".") == 2


def test_import_sid_loads_no_heavy_dependency():
    heavy = ("ompl", "onnxruntime", "cv2")
    code = f"import sys, sid; print(*[m for m in {heavy!r} if m in sys.modules])"
    result = subprocess.run([sys.executable, "-c", code], cwd=REPO_ROOT, capture_output=True, text=True, check=True)
    assert result.stdout.strip() == ""


def _module_files() -> list[Path]:
    return sorted(
        p
        for package in ("sid", "costmap", "planner")
        for p in (REPO_ROOT / package).rglob("*.py")
        if p.name != "__main__.py"
    )


def _literal_or_computed(value: ast.expr, module: str) -> list[str]:
    try:
        return list(ast.literal_eval(value))
    except ValueError:  # computed (sid/__init__.py: sorted(_EXPORTS)): the imported module's
        return list(importlib.import_module(module).__all__)


def _top_level_names(tree: ast.Module, module: str) -> tuple[set[str], list[str] | None]:
    """The public names a module defines (classes, functions, assignments) and its ``__all__`` (None: none)."""
    defined: set[str] = set()
    listed = None
    for node in tree.body:
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
            defined.add(node.name)
        targets = (
            node.targets if isinstance(node, ast.Assign) else [node.target] if isinstance(node, ast.AnnAssign) else []
        )
        for target in targets:
            if isinstance(target, ast.Name) and target.id == "__all__":
                listed = [] if node.value is None else _literal_or_computed(node.value, module)
            elif isinstance(target, ast.Name):
                defined.add(target.id)
    return {n for n in defined if not n.startswith("_")}, listed


@pytest.mark.parametrize("path", _module_files(), ids=lambda p: str(p.relative_to(REPO_ROOT)))
def test_every_module_lists_its_public_names_in_all(path: Path) -> None:
    module = ".".join(path.relative_to(REPO_ROOT).with_suffix("").parts).removesuffix(".__init__")
    defined, listed = _top_level_names(ast.parse(path.read_text()), module)
    if path.name == "__init__.py" and listed is None and not defined:
        return  # a package holding only a docstring
    assert listed is not None, f"{path}: no __all__"
    assert len(listed) == len(set(listed)), f"{path}: __all__ repeats a name"
    assert defined <= set(listed) or path.name == "__init__.py", (
        f"{path}: not in __all__: {sorted(defined - set(listed))}"
    )

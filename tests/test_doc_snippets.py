"""The Python snippets of README.md and docs/*.md (``python - ... <<'PY'`` blocks in ``sh`` fences) parse, and every
name they take from sid, costmap or planner exists, so a renamed function does not leave a measurement's command
broken. Running them needs ../shared and minutes each; their numbers are checked where they are written."""

from __future__ import annotations

import ast
import importlib
import re
import textwrap
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("sid", "costmap", "planner")
HEREDOC = re.compile(r"\bpython3? (?:-\S+ )*- .*<<\s*'(\w+)'")
FENCE = re.compile(r"^(\s*)```(\w*)")


@dataclass(frozen=True)
class Snippet:
    """A heredoc of Python in a fenced ``sh`` block: the file, the line of its ``python -`` command, its code."""

    path: Path
    line: int
    code: str
    outdented: tuple[int, ...] = ()  # lines (numbers in the file) less indented than their fence: they break it

    def __str__(self) -> str:
        return f"{self.path.relative_to(ROOT)}:{self.line}"


def snippets() -> list[Snippet]:
    found = []
    for path in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]:
        lines = path.read_text(encoding="utf-8").splitlines()
        shell: str | None = None  # the indentation of the open sh fence (None: no sh fence open)
        inside = False  # within any fence
        k = 0
        while k < len(lines):
            opened = FENCE.match(lines[k])
            if opened:
                inside = not inside
                shell = opened.group(1) if inside and opened.group(2) == "sh" else None
            elif shell is not None and (start := HEREDOC.search(lines[k])) and "PYTHONPATH=" not in lines[k]:
                # PYTHONPATH=. snippets run in a worktree of an older commit (docs/groups.md, "before the cones")
                end = next(j for j in range(k + 1, len(lines)) if lines[j].strip() == start.group(1))
                body = [line.removeprefix(shell) for line in lines[k + 1 : end]]
                outdented = tuple(
                    j + 1 for j in range(k + 1, end) if lines[j].strip() and not lines[j].startswith(shell)
                )
                found.append(Snippet(path, k + 1, "\n".join(body), outdented))
                k = end
            k += 1
    return found


SNIPPETS = snippets()


def test_the_documents_hold_snippets() -> None:
    assert len(SNIPPETS) >= 50


def _project_module(name: str) -> ModuleType | None:
    """The project module ``name`` (None: another package's); a skip when it needs an extra not installed."""
    if name.split(".")[0] not in PACKAGES:
        return None
    try:
        return importlib.import_module(name)
    except ModuleNotFoundError as exc:
        if exc.name is None or exc.name.split(".")[0] in PACKAGES:
            raise
        pytest.skip(f"{name} needs {exc.name}, an optional dependency not installed")


@pytest.mark.parametrize("snippet", SNIPPETS, ids=str)
def test_a_snippet_parses_and_names_what_exists(snippet: Snippet) -> None:
    assert not snippet.outdented, f"{snippet}: lines {snippet.outdented} are less indented than their fence"
    tree = ast.parse(textwrap.dedent(snippet.code), str(snippet))  # a SyntaxError names the file and line
    modules: dict[str, ModuleType] = {}  # the names bound to project modules
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                module = _project_module(alias.name)
                if module is not None:  # "import sid.x as m" binds m to sid.x, "import sid.x" binds sid
                    modules[alias.asname or alias.name.split(".")[0]] = (
                        module if alias.asname else importlib.import_module(alias.name.split(".")[0])
                    )
        elif isinstance(node, ast.ImportFrom) and node.module:
            module = _project_module(node.module)
            for alias in node.names if module is not None else ():
                value = getattr(module, alias.name, None)
                if value is None:  # a submodule not imported yet, or a name that is gone
                    try:
                        value = importlib.import_module(f"{node.module}.{alias.name}")
                    except ImportError:
                        raise AssertionError(f"{snippet}: {node.module} has no {alias.name}") from None
                if isinstance(value, ModuleType):
                    modules[alias.asname or alias.name] = value
    missing = [
        f"{node.value.id}.{node.attr}"
        for node in ast.walk(tree)
        if isinstance(node, ast.Attribute)
        and isinstance(node.value, ast.Name)
        and node.value.id in modules
        and isinstance(node.ctx, ast.Load)
        and not hasattr(modules[node.value.id], node.attr)
    ]
    assert not missing, f"{snippet}: {missing}"

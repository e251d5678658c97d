"""Reading the project's JSON / YAML input files (scenarios, scenes) with one rule and one set of errors."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any, TypeGuard

import yaml


def load_document(path: str | Path, kind: str = "file") -> Any:
    """Parsed content of a ``.json`` file (JSON) or any other file (YAML, which also reads JSON).

    Raises ValueError naming the file and ``kind`` (what the file should be): unreadable, or not valid JSON / YAML.
    """
    path = Path(path)
    try:
        text = path.read_text()
    except OSError as exc:
        raise ValueError(f"{path}: cannot read {kind} ({exc.strerror or exc})") from None
    is_json = path.suffix.lower() == ".json"
    try:
        return json.loads(text) if is_json else yaml.safe_load(text)
    except (json.JSONDecodeError, yaml.YAMLError) as exc:
        raise ValueError(f"{path}: not valid {'JSON' if is_json else 'YAML'} ({exc})") from None


def is_number(value: Any) -> TypeGuard[int | float]:
    """Whether a parsed JSON / YAML value is a finite number (an int or a float; booleans do not count)."""
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)

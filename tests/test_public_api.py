"""``import sid``: the public names resolve to their modules' objects, and importing sid alone stays cheap."""

from __future__ import annotations

import importlib
import subprocess
import sys

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


def test_version_is_a_plain_string():
    assert isinstance(sid.__version__, str) and sid.__version__.count(".") == 2


def test_import_sid_loads_no_heavy_dependency():
    heavy = ("ompl", "onnxruntime", "cv2")
    code = f"import sys, sid; print(*[m for m in {heavy!r} if m in sys.modules])"
    result = subprocess.run([sys.executable, "-c", code], cwd=REPO_ROOT, capture_output=True, text=True, check=True)
    assert result.stdout.strip() == ""

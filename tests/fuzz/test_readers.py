"""Fuzzing every input reader (issue 15): whatever the bytes or the values, a reader returns its record or raises
its documented error (a ValueError naming the file), with no other exception, no hang and bounded memory."""

from __future__ import annotations

import copy
import io
import json
import tempfile
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from costmap.mapfile import MapFileError, read_map
from sid.checks import limits
from sid.cli.groups import process
from sid.documents import InputWarning, load_document
from sid.experiments.fformation import load_dataset
from sid.perception.camera import Calibration
from sid.perception.groups import GroupParams
from sid.scenario.loader import ScenarioError, load_scenario
from tests.conftest import REPO_ROOT
from tests.fuzz.guards import bounded

EXAMPLE = json.loads((REPO_ROOT / "examples" / "conversation.json").read_text())
FUZZ = settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])

# JSON values as a parser may hand them over: edge numbers, strings, lists and mappings.
NUMBERS = st.sampled_from([0, -1, 1, 0.0, -0.0, 1e-300, 1e300, 10**30, float("nan"), float("inf"), 1e9, 1e6, 3])
SCALARS = st.none() | st.booleans() | NUMBERS | st.integers() | st.floats() | st.text(max_size=8)
VALUES = st.recursive(
    SCALARS,
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=6), inner, max_size=4),
    max_leaves=12,
)


def _paths(value: Any, prefix: tuple = ()) -> list[tuple]:
    """Every key path into a nested JSON value."""
    out = [prefix]
    if isinstance(value, dict):
        for key, item in value.items():
            out += _paths(item, (*prefix, key))
    elif isinstance(value, list):
        for index, item in enumerate(value):
            out += _paths(item, (*prefix, index))
    return out


EXAMPLE_PATHS = _paths(EXAMPLE)[1:]


@st.composite
def mutated_scenarios(draw: st.DrawFn) -> Any:
    """The example scenario with one to three fields (anywhere in it) replaced by arbitrary JSON values."""
    data = copy.deepcopy(EXAMPLE)
    for path in draw(st.lists(st.sampled_from(EXAMPLE_PATHS), min_size=1, max_size=3)):
        target = data
        try:
            for key in path[:-1]:
                target = target[key]
            target[path[-1]] = draw(VALUES)
        except (KeyError, IndexError, TypeError):  # an earlier replacement removed the path
            continue
    return data


def _write(folder: Path, name: str, data: bytes) -> Path:
    path = folder / name
    path.write_bytes(data)
    return path


@FUZZ
@given(st.binary(max_size=200), st.sampled_from([".json", ".yaml"]))
def test_any_bytes_read_as_a_document_or_a_named_error(raw, suffix):
    with tempfile.TemporaryDirectory() as folder, bounded():
        path = _write(Path(folder), f"doc{suffix}", raw)
        try:
            load_document(path, "scenario file")
        except ValueError as exc:
            assert str(exc).startswith(f"{path}: ")


@FUZZ
@given(mutated_scenarios())
def test_any_scenario_values_load_or_name_the_field(data):
    with tempfile.TemporaryDirectory() as folder, bounded():
        path = _write(Path(folder), "fuzz.json", json.dumps(data).encode())
        try:
            scenario = load_scenario(path)
        except ScenarioError as exc:
            assert str(exc).startswith(f"{path}: ") and "\n" not in str(exc)
        else:  # what loads stays within the limits
            assert scenario.grid.width * scenario.grid.height <= limits().map_cells
            assert len(scenario.people) <= limits().people


@st.composite
def map_files(draw: st.DrawFn) -> tuple[dict[str, Any], bytes]:
    """A map_server YAML mapping (some fields arbitrary) and image bytes (a PGM header of any size, or noise)."""
    meta: dict[str, Any] = {
        "image": "map.pgm",
        "resolution": 0.05,
        "origin": [0.0, 0.0, 0.0],
        "negate": 0,
        "occupied_thresh": 0.65,
        "free_thresh": 0.25,
        "mode": "trinary",
    }
    for key in draw(st.lists(st.sampled_from(sorted(meta)), max_size=2)):
        meta[key] = draw(VALUES)
    width, height = draw(st.integers(0, 10**6)), draw(st.integers(0, 10**6))
    header = f"P5\n{width} {height}\n255\n".encode()
    image = draw(
        st.sampled_from([header, header + bytes(64), b"", b"P5\n2 2\n255\n\x00\x10\x80\xff"]) | st.binary(max_size=64)
    )
    return meta, image


@FUZZ
@given(map_files())
def test_any_map_file_reads_or_names_the_file(case):
    meta, image = case
    with tempfile.TemporaryDirectory() as folder, bounded():
        _write(Path(folder), "map.pgm", image)
        path = _write(Path(folder), "map.yaml", json.dumps(meta).encode())
        try:
            grid = read_map(path)
        except MapFileError as exc:
            assert str(exc).startswith(f"{path}: ")
        else:
            assert grid.data.size <= limits().map_cells


CALIBRATION = {"width": 640, "height": 480, "fx": 525.0, "fy": 525.0, "cx": 319.5, "cy": 239.5}


@FUZZ
@given(
    st.dictionaries(
        st.sampled_from([*CALIBRATION, "color", "depth", "depth_to_color", "depth_scale"]), VALUES, max_size=4
    )
)
@example({"depth_to_color": 0})  # a number sid does not read in a flat calibration: an InputWarning
def test_any_calibration_reads_or_names_the_file(changes):
    with tempfile.TemporaryDirectory() as folder, bounded():
        path = _write(Path(folder), "calibration.json", json.dumps(CALIBRATION | changes).encode())
        try:
            with warnings.catch_warnings(record=True) as said:  # unread numbers, distortion: said, one line each
                warnings.simplefilter("always")
                Calibration.from_json(path)
        except ValueError as exc:
            assert str(path) in str(exc)
            return
    for warning in said:
        assert issubclass(warning.category, InputWarning), warning
        assert str(warning.message).startswith(f"calibration {path}: ") and "\n" not in str(warning.message)


LINES = st.lists(
    st.binary(max_size=40)
    | st.builds(lambda people: json.dumps({"frame": 0, "people": people}).encode(), st.lists(VALUES, max_size=4))
    | st.just(
        b'{"frame": 1, "people": [{"id": 1, "x": 0, "y": 0, "theta": 0}, {"id": 2, "x": 1, "y": 0, "theta": 3.1}]}'
    ),
    max_size=6,
)


@FUZZ
@given(LINES)
def test_any_json_lines_give_groups_or_numbered_problems(lines):
    out, err = io.StringIO(), io.StringIO()
    with bounded():
        code = process([line + b"\n" for line in lines], out, err, GroupParams())
    none_good = bool(err.getvalue()) and not out.getvalue() and any(line.strip() for line in lines)
    assert code == (2 if none_good else 0)
    for reported in err.getvalue().splitlines()[:-1]:  # the last line counts the skipped ones
        assert reported.startswith("sid groups: line ")
    assert all(set(json.loads(line)) == {"frame", "groups"} for line in out.getvalue().splitlines())


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.binary(max_size=300), st.sampled_from(["features.mat", "groundtruth.mat"]))
def test_any_mat_bytes_read_or_name_the_file(raw, name):
    with tempfile.TemporaryDirectory() as folder, bounded():
        _write(Path(folder), name, raw)
        try:
            load_dataset(folder)
        except ValueError as exc:
            assert "fformation: " in str(exc)


@pytest.mark.parametrize("name", ["features.mat", "groundtruth.mat"])
def test_mat_file_of_the_wrong_shape_names_the_file(tmp_path, name):
    scipy_io = pytest.importorskip("scipy.io")
    scipy_io.savemat(tmp_path / "features.mat", {"features": np.zeros((2, 2))})
    scipy_io.savemat(tmp_path / "groundtruth.mat", {"GTgroups": np.zeros((2, 2))})
    with pytest.raises(ValueError, match="fformation: "):
        load_dataset(tmp_path)

"""Input files that are not regular files (issue 29): every reader refuses a FIFO, a device or a folder by name
before opening it (opening a FIFO blocks, /dev/zero never ends), and JSON lines, which may come from a pipe, are read
with a bound on the line length."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import pytest

from costmap.mapfile import MapFileError, read_map
from sid.documents import load_document
from sid.experiments.fformation import load_dataset
from sid.experiments.seed_recordings import load_recording
from sid.experiments.trajectories import TrajectoryError, load_trajectory_set
from sid.perception.camera import Calibration
from sid.perception.pose.contracts import PoseModelError
from sid.perception.pose.session import OnnxModel
from sid.scenario.loader import ScenarioError, load_scenario
from sid.sources import FrameReadError, SourceError, open_source, skip_unreadable
from tests.conftest import REPO_ROOT
from tests.sources.test_folder_and_factory import INTR, write_pair


@pytest.fixture(params=["fifo", "device"])
def special(request, tmp_path) -> Callable[[Path], Path]:
    """Puts a FIFO, or a link to /dev/zero, at a path; what the reader must call it."""

    def make(path: Path) -> Path:
        path.parent.mkdir(parents=True, exist_ok=True)
        if request.param == "fifo":
            os.mkfifo(path)
        else:
            path.symlink_to("/dev/zero")
        return path

    make.words = "a FIFO (named pipe)" if request.param == "fifo" else "a character device"  # type: ignore[attr-defined]
    return make


def test_documents_scenarios_calibrations_and_maps_refuse_them(tmp_path, special):
    words = re.escape(f"it is {special.words}, not a regular file")
    scenario = special(tmp_path / "scenario.yaml")
    with pytest.raises(ValueError, match=f"scenario.yaml: cannot read scenario file: {words}"):
        load_document(scenario, "scenario file")
    with pytest.raises(ScenarioError, match=words):
        load_scenario(scenario)
    with pytest.raises(ValueError, match=f"calibration.json: cannot read calibration JSON: {words}"):
        Calibration.from_json(special(tmp_path / "calibration.json"))
    with pytest.raises(MapFileError, match=f"room.yaml: cannot read map YAML: {words}"):
        read_map(special(tmp_path / "room.yaml"))
    special(tmp_path / "map.pgm")
    (tmp_path / "map.yaml").write_text(
        "image: map.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.25\n"
    )
    with pytest.raises(MapFileError, match=f"map.yaml: cannot read map image .*map.pgm: {words}"):
        read_map(tmp_path / "map.yaml")


def test_datasets_recordings_and_models_refuse_them(tmp_path, special):
    words = re.escape(f"it is {special.words}, not a regular file")
    special(tmp_path / "ff" / "features.mat")
    with pytest.raises(ValueError, match=f"fformation: cannot read .*features.mat: {words}"):
        load_dataset(tmp_path / "ff")
    special(tmp_path / "eth" / "obsmat.txt")
    (tmp_path / "eth" / "groups.txt").write_text("")
    with pytest.raises(TrajectoryError, match=f"obsmat.txt: cannot read it: {words}"):
        load_trajectory_set(tmp_path / "eth")
    with pytest.raises(ValueError, match=f"cannot read .*log.csv: {words}"):
        load_recording(special(tmp_path / "log.csv"))
    with pytest.raises(PoseModelError, match=f"pose model .*model.onnx: {words}"):
        OnnxModel(special(tmp_path / "model.onnx"))
    with pytest.raises(SourceError, match=f"walk.mcap: {words}"):
        open_source(str(special(tmp_path / "walk.mcap")))


def test_a_frame_folder_skips_a_special_image_by_name_and_reads_its_calibration_by_name(tmp_path, special):
    write_pair(tmp_path / "color" / "0.png", tmp_path / "depth" / "0.png", 1500)
    special(tmp_path / "color" / "1.png")
    write_pair(tmp_path / "color" / "2.png", tmp_path / "depth" / "2.png", 1500)
    (tmp_path / "depth" / "1.png").write_bytes((tmp_path / "depth" / "0.png").read_bytes())
    (tmp_path / "intrinsics.json").write_text(json.dumps(INTR))
    errors: list[FrameReadError] = []
    frames = list(skip_unreadable(open_source(str(tmp_path)), errors.append))
    assert [f.index for f in frames] == [0, 2]
    assert [str(e) for e in errors] == [
        f"colour image {tmp_path / 'color' / '1.png'}: it is {special.words}, not a regular file"
    ]
    (tmp_path / "intrinsics.json").unlink()
    special(tmp_path / "intrinsics.json")
    with pytest.raises(
        SourceError, match=re.escape(f"intrinsics.json: cannot read calibration JSON: it is {special.words}")
    ):
        open_source(str(tmp_path))


def _sid(argv: list[str], **options) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "sid", *argv], cwd=REPO_ROOT, capture_output=True, timeout=120, **options
    )


def test_json_lines_refuse_a_device_and_read_a_fifo_as_a_stream(tmp_path):
    for command in ("groups", "track"):
        done = _sid([command, "/dev/zero"])
        assert done.returncode == 2
        assert (
            done.stderr.decode()
            == f"sid {command}: cannot read /dev/zero: it is a character device, not a regular file\n"
        )
    fifo = tmp_path / "frames.fifo"
    os.mkfifo(fifo)
    reader = subprocess.Popen(
        [sys.executable, "-m", "sid", "groups", str(fifo)],
        cwd=REPO_ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    line = {"frame": 7, "people": [{"id": 1, "x": 0, "y": 0, "theta": 0}, {"id": 2, "x": 1, "y": 0, "theta": 3.1}]}
    with open(fifo, "w") as writer:
        writer.write(json.dumps(line) + "\n")
    out, err = reader.communicate(timeout=120)
    assert reader.returncode == 0 and err == b""
    assert json.loads(out)["frame"] == 7


def test_endless_input_without_newlines_stops_at_the_line_bound():
    with open("/dev/zero", "rb") as zeros:  # on stdin, where any file may come: read with the bound
        done = _sid(["groups", "-"], stdin=zeros)
    assert done.returncode == 2 and done.stdout == b""
    assert done.stderr.decode() == (
        "sid groups: stdin: line 1 is longer than 16,777,216 bytes (no newline): not JSON lines; stopped there\n"
    )

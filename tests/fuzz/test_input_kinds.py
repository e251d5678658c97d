"""Fuzzing every input kind with structure (issue 29): JSON lines for ``sid groups`` and ``sid track`` with keys
given twice, misspelt or unknown; scenario YAML edited as text; PGM map headers; F-formation ``.mat`` files of any
cell contents; frame folders of any names, suffixes and pixels; and the JSON-lines commands run as processes under
memory and CPU limits. Each input either gives its documented result or its documented error, never another
exception, a hang or unbounded memory (``tests.fuzz.guards.bounded`` in this process, ``setrlimit`` in the
children)."""

from __future__ import annotations

import io
import json
import math
import resource
import subprocess
import sys
import tempfile
import warnings
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import scipy.io
import yaml
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st
from rosbags.serde import SerdeError

from costmap.mapfile import MapFileError, read_map
from sid.checks import limits
from sid.cli import groups, track
from sid.documents import InputWarning
from sid.experiments.fformation import load_dataset
from sid.perception.frame import Frame
from sid.perception.groups import GroupParams
from sid.scenario.loader import ScenarioError, load_scenario
from sid.sources import FrameReadError, SourceError, frames_or_errors
from sid.sources.folder import FolderSource
from sid.tracking import TrackingSession
from tests.conftest import REPO_ROOT
from tests.fuzz.guards import bounded
from tests.fuzz.test_readers import EXAMPLE, NUMBERS, VALUES

FUZZ = settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])

# --- JSON lines: objects whose keys may repeat, be misspelt or unknown ----------------------------------------------

Pairs = list[tuple[str, Any]]
"""A JSON object as its written key-value pairs (a key may come twice); a value is JSON or another Pairs."""


def _dumps(value: Any) -> str:
    """JSON text of ``value``, with ``Pairs`` objects written pair by pair (so a key can be given twice)."""
    if isinstance(value, tuple) and value and value[0] == "pairs":
        return "{" + ", ".join(f"{json.dumps(key)}: {_dumps(item)}" for key, item in value[1]) + "}"
    if isinstance(value, list):
        return "[" + ", ".join(_dumps(item) for item in value) + "]"
    return json.dumps(value)


def _keys_ok(value: Any, line_fields: tuple[str, ...], person_fields: tuple[str, ...]) -> bool:
    """Whether a written line object names only known fields, each once (the line and its people)."""
    if not (isinstance(value, tuple) and value[0] == "pairs"):
        return True
    keys = [key for key, _ in value[1]]
    if len(set(keys)) != len(keys) or not set(keys) <= set(line_fields):
        return False
    people = dict(value[1]).get("people")
    persons = people if isinstance(people, list) else []
    for person in persons:
        if isinstance(person, tuple) and person[0] == "pairs":
            names = [key for key, _ in person[1]]
            if len(set(names)) != len(names) or not set(names) <= set(person_fields):
                return False
    return True


@st.composite
def keyed_objects(draw: st.DrawFn, fields: dict[str, Any]) -> tuple[str, Pairs]:
    """``fields`` written as pairs, then edited: a key repeated, renamed (a typo), dropped, or a field added."""
    pairs: Pairs = list(fields.items())
    for _ in range(draw(st.integers(0, 2))):
        edit = draw(st.sampled_from(["repeat", "typo", "drop", "add", "value"]))
        if not pairs and edit != "add":
            continue
        at = draw(st.integers(0, max(len(pairs) - 1, 0)))
        if edit == "repeat":
            pairs.insert(draw(st.integers(0, len(pairs))), (pairs[at][0], draw(VALUES)))
        elif edit == "typo":
            key = pairs[at][0]
            cut = draw(st.integers(0, len(key)))
            pairs[at] = (key[:cut] + key[cut + 1 :] if cut < len(key) else key + "s", pairs[at][1])
        elif edit == "drop":
            pairs.pop(at)
        elif edit == "add":
            pairs.append((draw(st.sampled_from(["thta", "stamp", "Theta", "vx", "", "x "])), draw(VALUES)))
        else:
            pairs[at] = (pairs[at][0], draw(VALUES))
    return ("pairs", pairs)  # type: ignore[return-value]


def _person(draw: st.DrawFn, index: int) -> tuple[str, Pairs]:
    fields = {"id": index, "x": draw(NUMBERS | st.floats(-5, 5)), "y": draw(st.floats(-5, 5)), "theta": 0.5 * index}
    return draw(keyed_objects(fields))


@st.composite
def groups_lines(draw: st.DrawFn) -> list[Any]:
    """Lines of ``sid groups`` input as written objects (some edited)."""
    lines = []
    for number in range(draw(st.integers(1, 5))):
        people = [_person(draw, k) for k in range(draw(st.integers(0, 4)))]
        lines.append(draw(keyed_objects({"frame": number, "people": people})))
    return lines


@st.composite
def track_lines(draw: st.DrawFn) -> list[Any]:
    """Lines of ``sid track`` input as written objects (some edited), time going forward unless edited."""
    lines = []
    for number in range(draw(st.integers(1, 6))):
        people = [_person(draw, k) for k in range(draw(st.integers(0, 4)))]
        lines.append(draw(keyed_objects({"timestamp": number * 0.1, "people": people})))
    return lines


def _check_lines(command: str, written: list[Any], out: str, err: str, fields: tuple[tuple[str, ...], ...]) -> str:
    """Every line is an output line or a numbered problem; a line naming an unknown field or a key twice is never
    an output line. "clear" when a line was refused, else "accepted". Notes on lines that were read (a gap in the
    timestamps longer than the tracker's timeout) are neither."""
    outputs = out.splitlines()
    problems = [
        line for line in err.splitlines() if not line.startswith(f"{command}: skipped") and ": note: " not in line
    ]
    assert all(line.startswith(f"{command}: line ") for line in problems), problems
    assert len(outputs) + len(problems) == len(written)
    refused = {int(line.split()[3].rstrip(":")) for line in problems}
    for number, line in enumerate(written, start=1):
        if not _keys_ok(line, *fields):
            assert number in refused, (number, _dumps(line))
    assert all(isinstance(json.loads(line), dict) for line in outputs)
    return "clear" if problems else "accepted"


def check_groups_lines(written: list[Any]) -> str:
    out, err = io.StringIO(), io.StringIO()
    code = groups.process([_dumps(line) + "\n" for line in written], out, err, GroupParams())
    fields = (groups.LINE_FIELDS, groups.PERSON_FIELDS)
    return _check_exit(
        code, out.getvalue(), _check_lines("sid groups", written, out.getvalue(), err.getvalue(), fields)
    )


def check_track_lines(written: list[Any]) -> str:
    out, err = io.StringIO(), io.StringIO()
    code = track.process([_dumps(line) + "\n" for line in written], out, err, TrackingSession())
    fields = (track.LINE_FIELDS, track.PERSON_FIELDS)
    return _check_exit(code, out.getvalue(), _check_lines("sid track", written, out.getvalue(), err.getvalue(), fields))


def _check_exit(code: int, out: str, outcome: str) -> str:
    """The exit code of lines checked by ``_check_lines``: 2 when lines were refused and none written, else 0."""
    assert code == (2 if outcome == "clear" and not out else 0)
    return outcome


@FUZZ
@given(groups_lines())
@example([("pairs", [("frame", {"\x85": None}), ("people", [])])])  # U+0085 quoted raw split the message in two
def test_groups_lines_with_repeated_misspelt_or_unknown_keys_are_refused_by_number(written):
    with bounded():
        check_groups_lines(written)


@FUZZ
@given(track_lines())
def test_track_lines_with_repeated_misspelt_or_unknown_keys_are_refused_by_number(written):
    with bounded():
        check_track_lines(written)


# --- Scenario YAML edited as text ------------------------------------------------------------------------------------

EXAMPLE_YAML = yaml.safe_dump(EXAMPLE, sort_keys=False).splitlines()
SNIPPETS = st.sampled_from(
    ["", "  ", "\t", "- ", ": ", "{", "]", "&a [1, 2]", "*a", "<<: *a", "!!binary aGk=", "!!python/object:os.system",
     "? [1]", "5e-2", "1e400", "0x10", ".inf", ".nan", "~", "'", '"\\x00"', "%YAML 1.1", "---", "...", "é", "\x85"]
) | st.text(max_size=8)  # fmt: skip


@st.composite
def scenario_yaml(draw: st.DrawFn) -> str:
    """The example scenario as YAML with one to three lines repeated (a key twice), cut, replaced or extended."""
    lines = list(EXAMPLE_YAML)
    for _ in range(draw(st.integers(1, 3))):
        at = draw(st.integers(0, len(lines) - 1))
        edit = draw(st.sampled_from(["repeat", "cut", "replace", "append", "indent"]))
        if edit == "repeat":
            lines.insert(at, lines[at])
        elif edit == "cut":
            lines[at] = lines[at][: draw(st.integers(0, len(lines[at])))]
        elif edit == "replace":
            head = lines[at].split(":", 1)[0]
            lines[at] = f"{head}: {draw(SNIPPETS)}"
        elif edit == "append":
            lines[at] += draw(SNIPPETS)
        else:
            lines[at] = " " * draw(st.integers(0, 5)) + lines[at].lstrip()
    return "\n".join(lines) + "\n"


def check_scenario_yaml(text: str) -> str:
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "fuzz.yaml"
        path.write_text(text, encoding="utf-8", errors="surrogatepass")
        try:
            scenario = load_scenario(path)
        except ScenarioError as exc:
            assert str(exc).startswith(f"{path}: ") and "\n" not in str(exc)
            return "clear"
        assert len(scenario.people) <= limits().people
    return "accepted"


@FUZZ
@given(scenario_yaml())
def test_any_scenario_yaml_text_loads_or_names_the_file_in_one_line(text):
    with bounded():
        check_scenario_yaml(text)


# --- PGM map headers ----------------------------------------------------------------------------------------------


@st.composite
def pgm_maps(draw: st.DrawFn) -> bytes:
    """A PGM (P2 text or P5 binary) of a few pixels with comments anywhere in its header and any maximum value.
    Hypothesis leans to the first choice and the smallest value: readable maps come first, broken ones too."""
    width, height = draw(st.integers(1, 6) | st.just(0)), draw(st.integers(1, 6))
    maxval = draw(st.sampled_from([255, 1, 100, 256, 65535]) | st.sampled_from([0, 65536, 10**12]))
    comment = b"#" + b"c" * draw(st.sampled_from([0, 10, 1023, 1024, 5000])) + b"\n"
    magic = draw(st.sampled_from([b"P5", b"P2"]))
    header = magic + b"\n"
    for field in (width, height, maxval):  # a comment may come before any field after the magic number
        header += (comment if draw(st.booleans()) else b"") + str(field).encode() + b"\n"
    values = draw(
        st.lists(st.integers(0, max(min(maxval, 65535), 1)), min_size=width * height, max_size=width * height)
    )
    if magic == b"P2":
        body = b" ".join(str(v).encode() for v in values)
    else:
        body = b"".join(v.to_bytes(2 if maxval > 255 else 1, "big") for v in values)
    if draw(st.integers(0, 4)) == 4:  # cut short
        body = body[: draw(st.integers(0, len(body)))]
    return header + body


PGM_CASES = st.tuples(pgm_maps(), st.sampled_from(["trinary", "scale", "raw"]))


def check_pgm(case: tuple[bytes, str]) -> str:
    image, mode = case
    with tempfile.TemporaryDirectory() as folder:
        (Path(folder) / "map.pgm").write_bytes(image)
        path = Path(folder) / "map.yaml"
        meta = {"image": "map.pgm", "resolution": 0.05, "origin": [0, 0, 0], "negate": 0}
        path.write_text(json.dumps(meta | {"occupied_thresh": 0.65, "free_thresh": 0.25, "mode": mode}))
        try:
            grid = read_map(path)
        except MapFileError as exc:
            assert str(exc).startswith(f"{path}: ") and "\n" not in str(exc)
            return "clear"
    values = set(np.unique(grid.data).tolist())
    assert values <= {-1, *range(101)}, values
    return "accepted"


@FUZZ
@given(PGM_CASES)
def test_any_pgm_header_reads_as_a_grid_of_occupancy_values_or_names_the_file(case):
    with bounded():
        check_pgm(case)


# --- F-formation .mat files ---------------------------------------------------------------------------------------

CORRUPT_VALUES = st.sampled_from([math.nan, math.inf, -math.inf, 1e300, -1.0, 0.5, 1e9])


def _cell(items: list[Any]) -> np.ndarray:
    out = np.empty((1, len(items)), dtype=object)
    for k, item in enumerate(items):
        out[0, k] = item
    return out


@st.composite
def fformation_sets(draw: st.DrawFn) -> tuple[dict[str, Any], dict[str, Any]]:
    """features.mat and groundtruth.mat contents as the datasets store them (frames of [id, x, y, theta] rows in
    centimetres, groups of ids per stamped frame), then zero to two corruptions: a value made non-finite or huge, a
    frame's shape changed, a stamp repeated or removed, a variable missing."""
    count = draw(st.integers(1, 4))
    frames = []
    for _ in range(count):
        people = draw(st.integers(0, 5))
        rows = [
            [k + 1, draw(st.floats(-500, 500)), draw(st.floats(-500, 500)), draw(st.floats(-4, 4))]
            for k in range(people)
        ]
        frames.append(np.array(rows, float).reshape(people, 4))
    stamps = [float(t + 1) for t in range(count)]
    truth = [[draw(st.lists(st.integers(1, 5), min_size=2, max_size=3, unique=True))] for _ in range(count)]
    for _ in range(draw(st.integers(0, 2))):
        edit = draw(st.sampled_from(["value", "shape", "stamp", "group"]))
        at = draw(st.integers(0, count - 1))
        if edit == "value" and frames[at].size:
            frames[at].flat[draw(st.integers(0, frames[at].size - 1))] = draw(CORRUPT_VALUES)
        elif edit == "shape":
            frames[at] = np.zeros((draw(st.integers(0, 3)), draw(st.sampled_from([0, 1, 3, 5]))))
        elif edit == "stamp":
            stamps[at] = draw(st.sampled_from([stamps[0], math.nan, 0.0, 1e300]))
        else:
            truth[at] = [draw(st.lists(st.integers(-1, 9) | CORRUPT_VALUES, max_size=4))]
    features = {"features": _cell(frames), "timestamp": np.array([stamps], float)}
    groups = _cell([_cell([np.array([ids], float) for ids in groups]) for groups in truth])
    ground = {"GTgroups": groups, "GTtimestamp": np.array([stamps], float)}
    if draw(st.integers(0, 9)) == 0:
        data = draw(st.sampled_from([features, ground]))
        del data[draw(st.sampled_from(sorted(data)))]
    return features, ground


def check_fformation(case: tuple[dict[str, Any], dict[str, Any]]) -> str:
    features, truth = case
    with tempfile.TemporaryDirectory() as folder:
        scipy.io.savemat(Path(folder) / "features.mat", features)
        scipy.io.savemat(Path(folder) / "groundtruth.mat", truth)
        try:
            with warnings.catch_warnings(record=True) as said:  # e.g. extra feature columns: said, one line each
                warnings.simplefilter("always")
                frames = load_dataset(folder)
        except ValueError as exc:
            assert str(exc).startswith("fformation: ") and "\n" not in str(exc)
            return "clear"
    for warning in said:
        assert issubclass(warning.category, InputWarning), warning
        assert str(warning.message).startswith("fformation: ") and "\n" not in str(warning.message)
    for frame in frames:
        assert all(math.isfinite(p.x) and math.isfinite(p.y) for p in frame.people)
        assert all(p.theta is None or math.isfinite(p.theta) for p in frame.people)
    return "accepted"


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(fformation_sets())
def test_any_fformation_cells_load_as_frames_of_finite_people_or_name_the_file(case):
    with bounded():
        check_fformation(case)


# --- Frame folders ------------------------------------------------------------------------------------------------

INTR = {"width": 16, "height": 12, "fx": 20.0, "fy": 20.0, "cx": 7.5, "cy": 5.5, "depth_scale_m": 0.001}
NAMES = st.sampled_from(["0", "1", "2", "10", "01", "²", "a", "A", "frame3", "x٣", "1.5", " ", "é"])


def _image(kind: str, color: bool) -> bytes:
    """Encoded image bytes of one kind: the calibration's size, another size, the wrong depth type, or not an image."""
    size = (INTR["height"], INTR["width"])
    if kind == "right":
        pixels = np.full((*size, 3), 90, np.uint8) if color else np.full(size, 1500, np.uint16)
    elif kind == "other size":
        pixels = np.zeros((5, 7, 3), np.uint8) if color else np.zeros((5, 7), np.uint16)
    elif kind == "8-bit":
        pixels = np.zeros(size, np.uint8)
    else:
        return {"garbage": b"\x89PNG\r\n\x1a\n garbage", "empty": b""}[kind]
    return cv2.imencode(".png", pixels)[1].tobytes()


@st.composite
def frame_folders(draw: st.DrawFn) -> dict[str, bytes]:
    """A sequence folder's files (relative path -> bytes): colour and depth images of drawn names, suffixes and
    contents (a name may have two colour files, or no depth), and a calibration (sometimes broken)."""
    files: dict[str, bytes] = {}
    kinds = st.sampled_from(["right", "right", "other size", "8-bit", "garbage", "empty"])
    for name in draw(st.lists(NAMES, max_size=5, unique=True)):
        for suffix in draw(st.lists(st.sampled_from([".png", ".jpg", ".PNG", ".jpeg"]), min_size=1, max_size=2)):
            files[f"color/{name}{suffix}"] = _image(draw(kinds), color=True)
        if draw(st.integers(0, 4)):
            files[f"depth/{name}.png"] = _image(draw(kinds), color=False)
    calibration = dict(INTR)
    if draw(st.integers(0, 5)) == 0:
        calibration[draw(st.sampled_from(sorted(INTR)))] = draw(VALUES)
    files["intrinsics.json"] = json.dumps(calibration).encode()
    return files


def check_frame_folder(files: dict[str, bytes]) -> str:
    with tempfile.TemporaryDirectory() as folder:
        root = Path(folder)
        for name in ("color", "depth"):
            (root / name).mkdir()
        for relative, data in files.items():
            (root / relative).write_bytes(data)
        try:
            source = FolderSource(root)
        except (SourceError, ValueError) as exc:
            assert str(root) in str(exc)
            return "clear"
        items = list(frames_or_errors(source))
    assert len(items) == len(source)
    for item in items:
        if isinstance(item, Frame):
            assert item.color.shape == (INTR["height"], INTR["width"], 3)
            assert item.depth.shape == (INTR["height"], INTR["width"])
            assert np.all(np.isfinite(item.depth) & (item.depth >= 0))
        else:
            assert isinstance(item, FrameReadError) and "\n" not in str(item)
    return "clear" if any(isinstance(item, FrameReadError) for item in items) else "accepted"


@FUZZ
@given(frame_folders())
def test_any_frame_folder_gives_frames_of_its_calibration_or_one_error_per_frame(files):
    with bounded():
        check_frame_folder(files)


# --- rosbag2 recordings -------------------------------------------------------------------------------------------

BAG_SIZE = (6, 8)  # height, width of the fuzzed bags' images


@st.composite
def camera_bags(draw: st.DrawFn) -> list[Any]:
    """The messages of a short realsense2_camera recording (``tests.sources.camera_bags``), then edits of single
    messages: a field of an image or the camera_info changed (encoding, size, step, data cut, stamp repeated or
    moved), or its bytes cut short; messages may also go missing."""
    from sid.perception.camera import Intrinsics
    from tests.sources.camera_bags import TYPES, camera_messages

    height, width = BAG_SIZE
    count = draw(st.integers(1, 4))
    pairs = [
        (np.full((height, width, 3), 40 * k, np.uint8), np.full((height, width), 1500, np.uint16)) for k in range(count)
    ]
    stamps = [100.0 + draw(st.sampled_from([0.0, 0.0, 0.1, 0.2])) * k for k in range(count)]
    messages = camera_messages(pairs, Intrinsics(width, height, 8.0, 8.0, 3.5, 2.5), stamps=stamps)
    for _ in range(draw(st.integers(0, 3))):
        if not messages:
            break
        at = draw(st.integers(0, len(messages) - 1))
        topic, msgtype, time_ns, raw = messages[at]
        edit = draw(st.sampled_from(["field", "cut", "drop"]))
        if edit == "drop":
            messages.pop(at)
            continue
        if edit == "cut":
            messages[at] = (topic, msgtype, time_ns, raw[: draw(st.integers(0, len(raw)))])
            continue
        try:
            message = TYPES.deserialize_cdr(raw, msgtype)
        except SerdeError:  # cut by an earlier edit
            continue
        if msgtype.endswith("CameraInfo"):
            field = draw(st.sampled_from(["k", "width", "height"]))
            value = {
                "k": np.array(draw(st.lists(CORRUPT_VALUES | st.just(0.0), min_size=9, max_size=9)), float),
                "width": draw(st.sampled_from([0, 1, width + 1, 2**31 - 1])),
                "height": draw(st.sampled_from([0, 1, height + 1])),
            }[field]
        else:
            field = draw(st.sampled_from(["encoding", "width", "height", "step", "data", "is_bigendian"]))
            value = {
                "encoding": draw(st.sampled_from(["bgr8", "rgba8", "mono8", "16UC1", "32FC1", "yuv422", "", "é"])),
                "width": draw(st.sampled_from([0, 1, width - 1, width + 1, 2**31 - 1])),
                "height": draw(st.sampled_from([0, 1, height + 1, 2**31 - 1])),
                "step": draw(st.sampled_from([0, 1, message.step - 1, message.step + 4, 2**31 - 1])),
                "data": message.data[: draw(st.integers(0, len(message.data)))],
                "is_bigendian": 1,
            }[field]
        setattr(message, field, value)
        messages[at] = (topic, msgtype, time_ns, TYPES.serialize_cdr(message, msgtype))
    return messages


def check_camera_bag(messages: list[Any]) -> str:
    """Each colour message is one Frame of the calibration's size with finite depth, or one FrameReadError, unless
    the recording cannot be opened (SourceError naming it)."""
    from sid.sources import open_source
    from tests.sources.camera_bags import COLOR, write_messages

    with tempfile.TemporaryDirectory() as folder, warnings.catch_warnings():
        warnings.simplefilter("ignore", InputWarning)  # a camera_info or depth message skipped: the CLI says so
        bag = write_messages(Path(folder) / "bag", messages)
        try:
            source = open_source(str(bag))
        except SourceError as exc:
            assert str(bag) in str(exc) and "\n" not in str(exc), exc
            return "clear"
        items = list(frames_or_errors(source))
    assert len(items) == sum(topic == COLOR for topic, *_ in messages)
    for item in items:
        if isinstance(item, Frame):
            assert item.color.shape == (*BAG_SIZE, 3) and item.depth.shape == BAG_SIZE
            assert np.all(np.isfinite(item.depth) & (item.depth >= 0))
        else:
            assert isinstance(item, FrameReadError) and "\n" not in str(item)
    return "clear" if any(isinstance(item, FrameReadError) for item in items) else "accepted"


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(camera_bags())
def test_any_camera_bag_gives_one_frame_or_one_error_per_colour_image(messages):
    with bounded():
        check_camera_bag(messages)


# --- The JSON-lines commands as processes, under memory and CPU limits ------------------------------------------

CHILD_MEMORY_BYTES = 2 * 1024**3
"""Address space a ``sid`` child may use (its imports take about 1 GB of it; an unbounded read fails, not swaps)."""
CHILD_CPU_S = 60


def _limited() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (CHILD_MEMORY_BYTES, CHILD_MEMORY_BYTES))
    resource.setrlimit(resource.RLIMIT_CPU, (CHILD_CPU_S, CHILD_CPU_S))


@settings(max_examples=6, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    st.sampled_from(["groups", "track"]),
    st.lists(
        st.binary(max_size=60) | groups_lines().map(lambda lines: "\n".join(map(_dumps, lines)).encode()), max_size=4
    ),
    st.booleans(),
)
def test_the_json_lines_commands_end_with_a_documented_code_under_memory_and_cpu_limits(command, chunks, strict):
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "in.jsonl"
        path.write_bytes(b"\n".join(chunks))
        argv = [sys.executable, "-m", "sid", command, str(path), *(["--strict"] if strict else [])]
        done = subprocess.run(argv, cwd=REPO_ROOT, capture_output=True, timeout=300, preexec_fn=_limited)
    err = done.stderr.decode(errors="replace")
    # 2: stopped at a bad line (--strict), or no line was good (the summary says so).
    assert done.returncode in (0, 2) and (done.returncode == 0 or strict or "no line was good" in err), err
    assert "Traceback" not in err and all(line.startswith(f"sid {command}: ") for line in err.splitlines()), err

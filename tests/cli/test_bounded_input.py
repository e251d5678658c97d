"""Bad input, round three (issue 29, sizes and numbers): every size bounded before it is allocated, every accepted
number safe to the end of the pipeline, degenerate geometry handled as geometry, errors short."""

from __future__ import annotations

import dataclasses
import json
import os
import struct
import subprocess
import sys
import warnings
import zlib
from pathlib import Path

import cv2
import numpy as np
import pytest

from costmap.layers.inflation import InflationParams
from costmap.layers.obstacle import ObstacleParams
from costmap.layers.social import SocialParams
from costmap.layers.tracked import TrackedPeopleParams
from costmap.mapfile import MapFileError, read_map
from sid.checks import LimitError, limits_from_environment, use_limits
from sid.cli import main
from sid.documents import InputWarning
from sid.experiments.simulate.world import load_world
from sid.perception.camera import Calibration, Intrinsics
from sid.perception.groups import GroupParams
from sid.perception.keypoints import PoseDetection
from sid.perception.lifting import lift_people
from sid.perception.mount import CameraMount
from sid.scenario.build import build_costmap
from sid.scenario.loader import LidarSpec, ScenarioError, scenario_from_dict
from tests.conftest import REPO_ROOT
from tests.experiments.test_fformation import write_sequence
from tests.pose_models import build_yolo_pose_model, yolo_candidate

EXAMPLE = REPO_ROOT / "examples" / "conversation.json"


def scenario(tmp_path: Path, change: dict | None = None, **sections: object) -> str:
    """The example scenario with top-level sections replaced (``sections``) and dotted fields set (``change``)."""
    data = json.loads(EXAMPLE.read_text()) | sections
    for dotted, value in (change or {}).items():
        *parents, last = dotted.split(".")
        node = data
        for key in parents:
            node = node.setdefault(key, {}) if isinstance(node, dict) else node[int(key)]
        node[last if isinstance(node, dict) else int(last)] = value
    path = tmp_path / "s.json"
    path.write_text(json.dumps(data))
    return str(path)


def error_line(capsys: pytest.CaptureFixture[str]) -> str:
    """The one stderr line of a refused run (no traceback)."""
    err = capsys.readouterr().err
    assert "Traceback" not in err and err.count("\n") == 1, err
    return err.strip()


# --- degenerate geometry -------------------------------------------------------------------------------------

ON_ONE_SPOT = [  # three people on one spot facing apart, a fourth nearby: the grouping forms a zone of no area
    {"id": 1, "x": 4.0, "y": -0.3, "theta": 1.5708},
    {"id": 2, "x": 4.0, "y": -0.3, "theta": -0.9},
    {"id": 3, "x": 4.0, "y": -0.3, "theta": -0.96},
    {"id": 4, "x": 4.0, "y": -0.3, "theta": 1.5708},
]


PICTURE = {"costmap": "costmap.png", "plan": "plan.png", "demo": "comparison.png"}


@pytest.mark.parametrize("method", ["ospace", "gcff", "rays", "paper"])
@pytest.mark.parametrize("command", ["costmap", "plan"])
def test_people_on_one_spot_are_geometry(tmp_path, capsys, command, method):
    path = scenario(tmp_path, people=ON_ONE_SPOT, groups={"method": method})
    extra = ["--planner", "grid"] if command == "plan" else []
    assert main([command, path, *extra, "--out", str(tmp_path / "out")]) == 0, capsys.readouterr().err
    assert (tmp_path / "out" / PICTURE[command]).is_file()


@pytest.mark.parametrize("command", ["costmap", "plan", "demo"])
def test_a_zone_of_no_area_without_a_margin_is_a_point_or_a_line(tmp_path, capsys, command):
    path = scenario(tmp_path, {"layers.social.group_margin": 0.0}, people=ON_ONE_SPOT, groups={"method": "gcff"})
    args = {"costmap": [path], "plan": [path, "--planner", "grid"], "demo": ["--scenario", path, "--planner", "grid"]}
    assert main([command, *args[command], "--out", str(tmp_path / "out")]) == 0, capsys.readouterr().err
    assert (tmp_path / "out" / PICTURE[command]).is_file()


# --- sizes read before they are allocated --------------------------------------------------------------------

MEASURED = """
import resource, sys
from sid.cli import main
code = main(sys.argv[1:])
print(f"peak RSS {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss // 1024} MB", file=sys.stderr)
sys.exit(code)
"""


def sid_measured(*args: str) -> tuple[int, list[str], float]:
    """``sid ARGS`` in a fresh process: its exit code, its stderr lines and its peak memory (RSS, MB)."""
    env = {**os.environ, "PYTHONPATH": str(REPO_ROOT)}
    done = subprocess.run(
        [sys.executable, "-c", MEASURED, *args], capture_output=True, text=True, env=env, cwd=REPO_ROOT, timeout=600
    )
    *lines, peak = done.stderr.strip().splitlines()
    assert "Traceback" not in done.stderr, done.stderr
    return done.returncode, lines, float(peak.split()[2])


def black_png(width: int, height: int) -> bytes:
    """A whole, valid PNG of ``width`` x ``height`` black pixels at 1 bit per pixel: a few hundred kilobytes that
    decode to width x height x 3 bytes (OpenCV's colour image), or x 1 (its depth image)."""

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    packer, row = zlib.compressobj(9), bytes(1 + (width + 7) // 8)  # filter byte 0, then the row's bits
    pixels = b"".join(packer.compress(row) for _ in range(height)) + packer.flush()
    header = struct.pack(">IIBBBBB", width, height, 1, 0, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", pixels) + chunk(b"IEND", b"")


INTRINSICS = {"width": 64, "height": 48, "fx": 60.0, "fy": 60.0, "cx": 32.0, "cy": 24.0, "depth_scale": 0.001}


@pytest.mark.parametrize("stream", ["color", "depth"])
def test_a_frame_whose_header_says_20000_by_20000_is_refused_before_decoding(tmp_path, stream):
    folder = tmp_path / "frames"
    folder.mkdir()
    (folder / "intrinsics.json").write_text(json.dumps(INTRINSICS))
    cv2.imwrite(str(folder / "color.png"), np.zeros((48, 64, 3), np.uint8))
    cv2.imwrite(str(folder / "depth.png"), np.full((48, 64), 1500, np.uint16))
    (folder / f"{stream}.png").write_bytes(black_png(20000, 20000))
    model = build_yolo_pose_model(tmp_path / "m.onnx", np.zeros((56, 8)), (64, 64))
    code, lines, peak = sid_measured("detect", "--source", str(folder), "--model", str(model))
    what = "colour" if stream == "color" else "depth"
    assert f"{what} image {folder / f'{stream}.png'} is 20000x20000, the calibration says 64x48" in lines[0]
    assert code == 2 and "0 frames with people, 1 skipped" in lines[-2]  # its one frame unreadable: bad input
    assert "no frame of the source could be read" in lines[-1]
    assert peak < 1000  # decoded, the colour image alone is 1.2 GB


MAP_YAML = "image: {image}\nresolution: {resolution}\norigin: [0.0, 0.0, 0.0]\nnegate: 0\noccupied_thresh: 0.65\n"
MAP_YAML += "free_thresh: 0.25\n"


def map_scenario(tmp_path: Path, image: str, content: bytes, resolution: str = "0.05") -> str:
    (tmp_path / image).write_bytes(content)
    (tmp_path / "room.yaml").write_text(MAP_YAML.format(image=image, resolution=resolution))
    data = json.loads(EXAMPLE.read_text())
    data["static_map"] = "room.yaml"
    path = tmp_path / "s.json"
    path.write_text(json.dumps(data))
    return str(path)


HEADERS_OPENCV_WOULD_TRUST = {
    "room.hdr": b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 30000 +X 30000\n" + b"\0" * 64,
    "room.pam": b"P7\nWIDTH 30000\nHEIGHT 30000\nDEPTH 1\nMAXVAL 255\nTUPLTYPE GRAYSCALE\nENDHDR\n",
}


@pytest.mark.parametrize("image", HEADERS_OPENCV_WOULD_TRUST)
def test_a_map_image_whose_header_cannot_be_read_cheaply_is_refused(tmp_path, image):
    path = map_scenario(tmp_path, image, HEADERS_OPENCV_WOULD_TRUST[image])
    code, lines, peak = sid_measured("costmap", path, "--out", str(tmp_path / "out"))
    assert code == 2 and len(lines) == 1
    assert f"room.yaml: cannot read map image {tmp_path / image}: not a PNG, JPEG, PGM/PPM, BMP or TIFF" in lines[0]
    assert peak < 1000


def test_a_pgm_with_a_long_header_comment_keeps_its_maximum(tmp_path):
    """The maximum (here 1: white) comes after a 2 KB comment; missed, every white (free) cell read as occupied."""
    comment = b"# " + b"x" * 2000 + b"\n"
    path = map_scenario(tmp_path, "room.pgm", b"P5\n" + comment + b"200 160\n1\n" + bytes([1]) * 32000)
    assert read_map(tmp_path / "room.yaml").data.max() == 0  # every cell free
    assert main(["costmap", path, "--out", str(tmp_path / "out")]) == 0


def test_an_exponent_without_a_point_is_a_number_as_in_nav2(tmp_path):
    map_scenario(tmp_path, "room.pgm", b"P5\n20 16\n255\n" + bytes([254] * 320), resolution="5e-2")
    assert read_map(tmp_path / "room.yaml").spec.resolution == 0.05


# --- numbers: a range each, said in the error ----------------------------------------------------------------

OUT_OF_RANGE = [  # field, value, what the one-line error says
    ("layers.social.sigma_front", 5e-324, "social: sigma_front must be a finite number of metres in [0.001, 1000]"),
    ("layers.social.sigma_side", 1e300, "social: sigma_side must be a finite number of metres in [0.001, 1000]"),
    ("layers.social.group_sigma", 1e-300, "social: group_sigma must be a finite number of metres in [0.001, 1000]"),
    ("layers.social.people_clear_margin", 1e300, "people_clear_margin must be a finite number of metres in [0, 1000]"),
    ("lidar.body_radius", 1e300, "lidar.body_radius: 1e+300 m is more than the map's diagonal (12.8062 m)"),
    ("robot.radius", 1e300, "robot.radius: 1e+300 m is more than the map's diagonal (12.8062 m)"),
    ("map.origin", [1e300, -4.0], "map: origin_x must be a finite number of metres in [-1e+07, 1e+07], got 1e+300"),
    ("groups.radius_steps", 1000000, "groups: radius_steps must be a whole number from 1 to 100, got 1000000"),
    ("groups.body_radius", 1e300, "groups: body_radius must be a finite number of metres in [0, 1000]"),
    ("groups.unknown_facing_cost", 1e300, "groups: unknown_facing_cost must be a finite number of metres in [0, 1000]"),
    ("layers.obstacle.raytrace_max_range", 1e300, "720 beams x 2e+301 cells of range (1e+300 m at 0.05 m) = 1.44e+304"),
]


@pytest.mark.parametrize(("field", "value", "message"), OUT_OF_RANGE)
def test_a_number_downstream_code_cannot_take_is_refused_with_its_range(tmp_path, capsys, field, value, message):
    assert main(["plan", scenario(tmp_path, {field: value}), "--planner", "grid", "--out", str(tmp_path)]) == 2
    line = error_line(capsys)
    assert message in line and len(line) < 300, line


def test_the_numbers_at_the_ends_of_their_ranges_run_to_the_end(tmp_path, capsys):
    """Each field at an end of its range still gives a costmap (no overflow, no drawing error), and a map at the
    farthest origin the same plan as at home."""
    ends = {f"layers.social.{name}": 1000.0 for name in ("sigma_front", "sigma_rear", "sigma_side", "sigma_unknown")}
    ends |= {"layers.social.group_sigma": 1e-3, "groups.radius_steps": 100, "lidar.body_radius": 12.8}
    ends |= {"robot.radius": 12.8, "layers.social.group_margin": 1000.0}
    assert main(["costmap", scenario(tmp_path, ends), "--out", str(tmp_path / "a")]) == 0
    # The farthest origin, people, robot and walls moved with the map: the same personal spaces as at home.
    shift = np.array([-1e7 + 1.0, 1e7 - 4.0])
    data = json.loads(EXAMPLE.read_text())
    data["map"]["origin"] = (np.array(data["map"]["origin"]) + shift).tolist()
    for person in data["people"]:
        person["x"], person["y"] = (np.array([person["x"], person["y"]]) + shift).tolist()
    for end in ("start", "goal"):
        data["robot"][end][:2] = (np.array(data["robot"][end][:2]) + shift).tolist()
    for obstacle in data["obstacles"]:
        for key in ("points", "center", "min", "max"):
            if key in obstacle:
                obstacle[key] = (np.array(obstacle[key]) + shift).tolist()
    (tmp_path / "far.json").write_text(json.dumps(data))
    for name, path in (("far", tmp_path / "far.json"), ("home", EXAMPLE)):
        assert main(["costmap", str(path), "--out", str(tmp_path / name)]) == 0
    far, home = (np.load(tmp_path / name / "costmap.npz") for name in ("far", "home"))
    assert far["origin"].tolist() == [-1e7, 1e7 - 8.0]
    assert np.count_nonzero(home["layer_social"]) > 3000 and np.array_equal(far["layer_social"], home["layer_social"])
    assert main(["plan", str(tmp_path / "far.json"), "--planner", "grid", "--out", str(tmp_path / "plan")]) == 0


def test_obstacle_points_are_counted_before_they_are_read(tmp_path, capsys):
    wall = [{"type": "segment", "points": [[0.0, 0.01 * (i % 2)] for i in range(200_000)]}]
    code, lines, peak = sid_measured("costmap", scenario(tmp_path, obstacles=wall), "--out", str(tmp_path / "out"))
    assert code == 2 and lines == [
        f"sid costmap: {tmp_path / 's.json'}: obstacles: 200,000 points is more than the limit of 100,000 points "
        "(obstacle_points; raise it with SID_LIMITS=obstacle_points=N)"
    ]
    assert peak < 1000
    boxes = [{"type": "box", "min": [0.0, 0.0], "max": [0.1, 0.1]}] * 100_000
    assert main(["costmap", scenario(tmp_path, obstacles=boxes), "--out", str(tmp_path / "out")]) == 2
    assert "obstacles: 400,000 points is more than the limit" in error_line(capsys)


def test_the_scan_bounds_its_ray_tests(tmp_path, capsys):
    """Beams x edges is a limit of its own; below it the scan's arrays stay small whatever the walls."""
    wall = [{"type": "segment", "points": [[-1.0 + 1e-4 * i, 0.01 * (i % 2)] for i in range(30_000)]}]
    assert main(["costmap", scenario(tmp_path, obstacles=wall), "--out", str(tmp_path / "out")]) == 2
    assert "lidar: 720 beams x 30,003 edges = 21,602,160 ray tests is more than the limit of 20,000,000" in (
        error_line(capsys)
    )
    below = [{"type": "segment", "points": wall[0]["points"][:20_000]}]  # 720 x 20,003 = 14.4 million ray tests
    code, lines, peak = sid_measured("costmap", scenario(tmp_path, obstacles=below), "--out", str(tmp_path / "o"))
    assert code == 0 and peak < 1000


LEVELS = "abcdefghi"
ALIAS_BOMB = (
    "[&a [x, x, x, x, x, x, x, x, x], "
    + ", ".join(f"&{k} [{', '.join([f'*{p}'] * 9)}]" for p, k in zip(LEVELS, LEVELS[1:], strict=False))
    + "]"
)


def test_an_alias_bomb_in_a_refused_field_is_not_expanded(tmp_path):
    """Nine levels of nine aliases: 9^9 (387 million) items once expanded, about 400 bytes on disk."""
    path = tmp_path / "bomb.yaml"
    path.write_text(f"name: {ALIAS_BOMB}\nrobot: {{start: [0, 0], goal: [1, 0]}}\n")
    code, lines, peak = sid_measured("costmap", str(path), "--out", str(tmp_path / "out"))
    assert len(path.read_bytes()) < 500 and code == 2 and len(lines) == 1
    assert lines[0].startswith(f'sid costmap: {path}: name: expected a non-empty string, got [["x", "x", "x"')
    assert len(lines[0]) < 300 and peak < 1000


# --- the pose model's answers ----------------------------------------------------------------------------------


def one_frame_folder(tmp_path: Path) -> Path:
    """A frame folder of one 64 x 48 frame, everything 1.5 m away."""
    folder = tmp_path / "frames"
    folder.mkdir()
    (folder / "intrinsics.json").write_text(json.dumps(INTRINSICS))
    cv2.imwrite(str(folder / "color.png"), np.full((48, 64, 3), 128, np.uint8))
    cv2.imwrite(str(folder / "depth.png"), np.full((48, 64), 1500, np.uint16))
    return folder


def test_a_model_answering_20000_people_keeps_the_best_100(tmp_path):
    """20,000 small boxes that NMS keeps apart (input pixels of a 256 x 256 model): the frame keeps the 100 best."""
    side = np.arange(142) * 1.8 + 2.0
    cx, cy = (a.ravel()[:20_000] for a in np.meshgrid(side, side))
    spread = np.linspace(-0.4, 0.4, 17)
    candidates = np.stack(
        [
            yolo_candidate((x, y, 1.0, 1.0), 0.5 + 0.4 * (k % 997) / 997, np.stack([x + spread, y + spread[::-1]], 1))
            for k, (x, y) in enumerate(zip(cx, cy, strict=True))
        ],
        axis=1,
    )
    model = build_yolo_pose_model(tmp_path / "m.onnx", candidates, (256, 256))
    code, lines, peak = sid_measured("detect", "--source", str(one_frame_folder(tmp_path)), "--model", str(model))
    assert code == 0 and lines[0] == (
        "sid detect: warning: pose: the model found 20,000 people in one frame, more than the limit of 100 "
        "detections; the 100 highest-scoring kept (detections; raise it with SID_LIMITS=detections=N)"
    )
    assert peak < 1000


def test_a_model_answering_no_candidates_is_refused_when_it_loads(tmp_path, capsys):
    model = build_yolo_pose_model(tmp_path / "m.onnx", np.zeros((56, 0)), (64, 64))
    assert main(["detect", "--source", str(one_frame_folder(tmp_path)), "--model", str(model)]) == 2
    assert "the model answers no candidates (output [1, 56, 0])" in error_line(capsys)


def test_lifting_refuses_more_detections_than_the_limit():
    detection = PoseDetection(np.full((17, 2), 30.0), np.ones(17), np.array([28.0, 28, 32, 32]), 0.9)
    calibration = Calibration(Intrinsics.from_dict(INTRINSICS))
    with pytest.raises(LimitError, match="lift: detections: 101 detections is more than the limit of 100"):
        lift_people([detection] * 101, np.full((48, 64), 1.5), calibration, CameraMount())


def test_a_mirror_or_a_baseline_in_millimetres_as_depth_to_colour_is_refused(tmp_path):
    folder = one_frame_folder(tmp_path)
    sections = {k: v for k, v in INTRINSICS.items() if k != "depth_scale"}  # a stream's section has no depth scale
    mirror = [[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]  # orthonormal, determinant -1
    extrinsics = {"rotation": mirror, "translation": [0.0, 0.0, 0.0]}
    (folder / "intrinsics.json").write_text(
        json.dumps({"color": sections, "depth": sections, "depth_to_color": extrinsics})
    )
    with pytest.raises(ValueError, match="depth_to_color: rotation has determinant -1, a mirror rather than a rota"):
        Calibration.from_json(folder / "intrinsics.json")
    millimetres = {"rotation": np.eye(3).tolist(), "translation": [15.0, 0.0, 0.0]}  # 15 mm written as 15 m
    (folder / "intrinsics.json").write_text(
        json.dumps({"color": sections, "depth": sections, "depth_to_color": millimetres})
    )
    with pytest.raises(ValueError, match="depth_to_color: translation 15 m is more than 1 m; the two sensors"):
        Calibration.from_json(folder / "intrinsics.json")


def test_eval_fformation_has_the_per_frame_people_limit_of_sid_groups(tmp_path, capsys):
    crowd = np.array([[k + 1, 100.0 * (k % 60), 100.0 * (k // 60), 0.0] for k in range(3000)])
    folder = write_sequence(tmp_path / "Crowd", [crowd], {1: [[1, 2]]})
    assert main(["eval", "fformation", str(folder), "--method", "paper"]) == 2
    line = error_line(capsys)
    assert "frame at timestamp 1: features: 3,000 people is more than the limit of 100 people (people; raise" in line


def _numeric_fields() -> list[str]:
    """Every number a scenario file sets: each parameter record's numeric fields, the LiDAR's, and those of the
    example's map, obstacles, people and robot."""
    records = {
        "layers.obstacle": ObstacleParams,
        "layers.inflation": InflationParams,
        "layers.social": SocialParams,
        "layers.tracked_people": TrackedPeopleParams,
        "groups": GroupParams,
        "lidar": LidarSpec,
    }
    fields = [
        f"{section}.{f.name}"
        for section, record in records.items()
        for f in dataclasses.fields(record)
        if type(getattr(record(), f.name)) in (int, float)
    ]
    return fields + [
        *("map.resolution", "map.origin.0", "map.size.1", "obstacles.3.radius", "obstacles.3.center.0"),
        *(
            "obstacles.0.points.1.0",
            "obstacles.4.max.1",
            "people.0.x",
            "people.0.theta",
            "people.1.orientation_quality",
        ),
        *("robot.radius", "robot.speed", "robot.start.2", "robot.goal.0"),
    ]


EXTREMES = [5e-324, 1e-300, 1e-9, 0, -1e300, 1e300, 1e6, 10**6, 100, 7]


@pytest.mark.parametrize("field", _numeric_fields())
def test_every_number_at_its_extremes_builds_a_costmap_or_names_the_field(field):
    """The class, not the examples: each numeric field at each extreme loads and builds (no warning, no overflow) or
    is refused in one short line naming the field."""
    for value in EXTREMES:
        data = json.loads(EXAMPLE.read_text())
        *parents, last = field.split(".")
        node = data
        for key in parents:
            node = node.setdefault(key, {}) if isinstance(node, dict) else node[int(key)]
        node[last if isinstance(node, dict) else int(last)] = value
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # numpy's overflow and invalid-cast warnings included
            # A circle as wide as the map holds the people: that one warning names them, by design.
            warnings.filterwarnings("ignore", "people.*stands in an occupied cell of the known map", InputWarning)
            try:
                build_costmap(scenario_from_dict(data))
            except ScenarioError as exc:
                assert len(str(exc)) < 300 and "\n" not in str(exc), exc


def test_a_simulation_of_too_many_steps_is_refused_before_it_runs(tmp_path, capsys):
    path = scenario(tmp_path, simulation={"time_limit_s": 1e300, "rate_hz": 10})
    assert main(["simulate", path, "--out", str(tmp_path / "out")]) == 2
    assert "simulation: 1e+300 s x 10 Hz = 1e+301 steps is more than the limit of 6,000 steps (sim_steps; raise" in (
        error_line(capsys)
    )


def test_sid_limits_raises_the_new_limits(tmp_path, monkeypatch):
    boxes = [{"type": "box", "min": [0.0, 0.0], "max": [0.1, 0.1]}] * 30
    path = scenario(tmp_path, obstacles=boxes, simulation={"time_limit_s": 100, "rate_hz": 100})
    refusals = {  # SID_LIMITS -> the refusal; each raised in turn
        "sim_steps=5000": "simulation: 100 s x 100 Hz = 10,000 steps is more than the limit of 5,000",
        "sim_steps=10000,obstacle_points=100": "obstacles: 120 points is more than the limit of 100 points",
        "sim_steps=10000,obstacle_points=120,scan_edges=50000": "720 beams x 124 edges = 89,280 ray tests is more",
    }
    for setting, message in refusals.items():
        monkeypatch.setenv("SID_LIMITS", setting)
        with use_limits(limits_from_environment()), pytest.raises(ScenarioError, match=message):
            load_world(path)
    monkeypatch.setenv("SID_LIMITS", "sim_steps=10000,obstacle_points=120,scan_edges=90000")
    with use_limits(limits_from_environment()):
        assert len(load_world(path).scenario.obstacles) == 30


def test_a_calibration_larger_than_the_image_limit_is_refused_before_any_frame(tmp_path, capsys):
    folder = one_frame_folder(tmp_path)
    huge = INTRINSICS | {"width": 100_000, "height": 100_000, "cx": 50_000.0, "cy": 50_000.0, "fx": 50_000.0}
    (folder / "intrinsics.json").write_text(json.dumps(huge | {"fy": 50_000.0}))
    model = build_yolo_pose_model(tmp_path / "m.onnx", np.zeros((56, 8)), (64, 64))
    assert main(["detect", "--source", str(folder), "--model", str(model)]) == 2
    assert "intrinsics: image: 100000 x 100000 = 10,000,000,000 pixels is more than the limit of 33,177,600 pixels" in (
        error_line(capsys)
    )


def test_a_map_yaml_origin_too_far_is_refused_before_its_image_is_read(tmp_path):
    map_scenario(tmp_path, "room.pgm", b"P5\n20 16\n255\n" + bytes([254] * 320))
    (tmp_path / "room.yaml").write_text((tmp_path / "room.yaml").read_text().replace("[0.0, 0.0", "[1e300, 0.0"))
    with pytest.raises(MapFileError, match=r"room.yaml: 'origin' x and y must lie within 1e\+07 m, got \[1e\+300, 0.0"):
        read_map(tmp_path / "room.yaml")

"""The stages ``sid bench`` times, each on a fixed, seeded input, and what each corresponds to in the paper.

Every benchmark returns one or more stage records ``{"median_ms", "min_ms", "max_ms", "runs", ...extra}``
keyed by stage name. Extra fields: ``paper_ms`` (the paper's Table 2 figure for the same step, from a Jetson Orin
NX, another machine; docs/benchmarks.md), ``ratio_to`` (the stage this one is compared with:
``sid.experiments.bench.suite`` adds ``ratio`` = this median / that median), and counts or checks that show the
stage did its work.

Each benchmark imports what it times inside its own function, so that a module that fails to import (or an
optional piece missing on a machine) costs only the benchmarks that need it, reported as such, not the run.
"""

from __future__ import annotations

import importlib.util
import math
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from sid.distribution import install_hint
from sid.experiments.bench.baseline import BaselineGroup, baseline_groups
from sid.experiments.bench.pose import timed_call
from sid.experiments.bench.runner import RunSettings, Stats, measure, measure_parts
from sid.perception.people import Person

if TYPE_CHECKING:
    from sid.experiments.bench.crowd_scene import CrowdReplay
    from sid.experiments.harness import Task
    from sid.perception.align import SplatMode
    from sid.perception.frame import Frame
    from sid.perception.group import Group
    from sid.perception.keypoints import PoseDetection
    from sid.perception.pose import MoveNetMultiPose, MoveNetSinglePose, YoloPose
    from sid.synthetic import Scene

__all__ = [
    "ALIGN_MODES",
    "Benchmark",
    "CROWD_FPS",
    "CROWD_RESOLUTION",
    "CROWD_SETS",
    "CROWD_SIZES",
    "CROWD_SPACING",
    "CROWD_TARGET_MS",
    "CROWD_WARMUP_FRAMES",
    "Context",
    "DBSCAN_SIZES",
    "FRAME_SIZES",
    "GROUPING_THREADS",
    "GROUP_SIZES",
    "PAPER_GROUP_MAX",
    "PAPER_GROUP_MS",
    "PAPER_LIFT_MS",
    "PAPER_POSE_MS",
    "PAPER_TOTAL_MS",
    "Records",
    "TRACK_FPS",
    "TRACK_SIZES",
    "benchmarks",
    "crowd_sets",
    "grouping_scene",
    "pose_models",
    "real_rgbd_folders",
    "record",
]

GROUP_SIZES = (2, 3, 4, 6, 20, 100)
# The ray methods above this many people: the authors' approach and sid's `paper` method prune one crowd member by
# member (minutes at 100 people), so their rows stop here.
PAPER_GROUP_MAX = 20
CROWD_SPACING = 2.4  # m between the centres of the circles of grouping_scene
DBSCAN_SIZES = (4, 20)
FRAME_SIZES = (2, 3, 4, 6)
ALIGN_MODES: tuple[SplatMode, ...] = ("rectangle", "point")

# The paper's Table 2 (ms per frame on a Jetson Orin NX; docs/benchmarks.md) for 2 / 3 / 4 people.
PAPER_POSE_MS = {2: 3.15, 3: 2.86, 4: 3.32}
PAPER_LIFT_MS = {2: 0.55, 3: 0.52, 4: 0.55}  # "depth alignment + 3D"
PAPER_GROUP_MS = {2: 0.25, 3: 0.14, 4: 0.15}  # "DBSCAN + groups"
PAPER_TOTAL_MS = {2: 3.95, 3: 3.52, 4: 4.02}

Records = dict[str, dict[str, Any]]


@dataclass
class Context:
    """What every benchmark may use: timing settings, where ../shared is, shared set-ups and notes for the report.

    plan_runs: seeds per sampling planner (each run takes the whole 0.5 s budget). pose_threads, pose_provider:
    the pose sessions' thread count (None: physical cores) and execution provider (``load_pose_estimator``'s).
    """

    settings: RunSettings
    shared: Path
    plan_runs: int
    pose_threads: int | None = None
    pose_provider: str = "auto"
    notes: list[str] = field(default_factory=list)
    _cache: dict[str, Any] = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        if self.plan_runs < 1:
            raise ValueError(f"bench: plan_runs must be at least 1, got {self.plan_runs}")

    def cached(self, key: str, build: Callable[[], Any]) -> Any:
        """``build()`` once per run, shared by the benchmarks that need the same input."""
        if key not in self._cache:
            self._cache[key] = build()
        return self._cache[key]

    def note(self, text: str) -> None:
        if text not in self.notes:
            self.notes.append(text)


@dataclass(frozen=True)
class Benchmark:
    """One unit of ``sid bench``: its name (also the prefix of the stages it writes), a one-line description, the
    function that times it, and the benchmarks whose stages its ratios refer to (run with it)."""

    name: str
    what: str
    run: Callable[[Context], Records]
    needs: tuple[str, ...] = ()


def record(stats: Stats, **extra: Any) -> dict[str, Any]:
    """A stage record: the fixed fields plus extras (None values are left out)."""
    return stats.to_dict() | {k: v for k, v in extra.items() if v is not None}


# --- scenes -------------------------------------------------------------------------------------------------------


def grouping_scene(n: int, seed: int = 0) -> list[Person]:
    """``n`` people in conversation circles facing their centre, world frame (metres, radians).

    Up to 6 people stand in one circle (radius 0.4 m for 2, i.e. 0.8 m apart as the paper's S1; 0.69 m for 3;
    0.8 m for 4-5; 0.85 m for 6: neighbours 0.8-0.85 m apart); more are split into circles of 4 whose centres lie
    2.4 m apart on a square grid: one crowd, strangers 0.8 m apart across neighbouring circles, one DBSCAN cluster
    at the ray methods' eps (2 m). Positions get 3 cm and facings 3 degrees of
    seeded Gaussian noise, so that rays cross at distinct points as they do on real estimates (exact rays all meet
    in one point).
    """
    if n < 1:
        raise ValueError(f"bench: a grouping scene needs at least one person, got {n}")
    sizes = [n] if n <= 6 else [4] * (n // 4) + ([n % 4] if n % 4 else [])
    radius = {1: 0.4, 2: 0.4, 3: 0.69, 4: 0.8, 5: 0.8, 6: 0.85}
    rng = np.random.default_rng(seed)
    people: list[Person] = []
    columns = math.ceil(math.sqrt(len(sizes)))
    for k, size in enumerate(sizes):
        cx, cy = 2.5 + CROWD_SPACING * (k % columns), CROWD_SPACING * (k // columns)
        for j in range(size):
            angle = 2 * math.pi * j / size + 0.3
            x = cx + radius[size] * math.cos(angle) + rng.normal(0.0, 0.03)
            y = cy + radius[size] * math.sin(angle) + rng.normal(0.0, 0.03)
            theta = math.atan2(cy - y, cx - x) + rng.normal(0.0, math.radians(3.0))
            people.append(Person(len(people), x, y, theta, 1.0))
    return people


def _frame_scene(n: int) -> Scene:
    """The synthetic scene of the per-frame pipeline: the paper's S1 (2 people), S3 (3), S5 (4), or 6 people on a
    1 m circle 3 m in front of the camera, facing its centre."""
    from sid.synthetic import Scene, ScenePerson, layout

    if n in (2, 3, 4):
        return layout({2: "S1", 3: "S3", 4: "S5"}[n])
    angles = [2 * math.pi * k / n + math.pi / n for k in range(n)]
    people = tuple(
        ScenePerson(k, 3.0 + math.cos(a), math.sin(a), math.atan2(-math.sin(a), -math.cos(a)))
        for k, a in enumerate(angles)
    )
    return Scene(f"circle{n}", people, (tuple(range(n)),))


def _frames(ctx: Context, n: int, count: int = 4) -> list[Frame]:
    """``count`` synthetic RGB-D frames (D435i depth 848x480 with noise, colour grid 1280x720) of ``n`` people."""

    def build() -> list[Frame]:
        from sid.synthetic import SyntheticCamera

        camera = SyntheticCamera(shaded_color=False)  # the colour image is not used: faster rendering
        scene = _frame_scene(n)
        return [camera.capture(scene, index=i, seed=0) for i in range(count)]

    return ctx.cached(f"frames/{n}", build)


def _truth_detections(frame: Frame) -> list[PoseDetection]:
    from sid.synthetic.pose import TruthPose

    return TruthPose()(frame)


# --- grouping -----------------------------------------------------------------------------------------------------

# The grouping stages run with native thread pools (OpenMP, BLAS) limited to one thread: the work is tiny, and
# scikit-learn's OpenMP pool (DBSCAN's brute-force neighbour search on small inputs) is many times slower while
# other processes keep the cores busy (docs/benchmarks.md, "Grouping threads"); one thread is how such a step runs
# next to a camera driver and a planner. threadpoolctl is a dependency of scikit-learn, not an extra one.
GROUPING_THREADS = 1


def _measure_one_thread(fn: Callable[[], object], settings: RunSettings) -> Stats:
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=GROUPING_THREADS):
        return measure(fn, settings)


def _member_sets(groups: Iterable[Group | BaselineGroup]) -> set[tuple[int, ...]]:
    return {tuple(sorted(g.members)) for g in groups}


def _bench_group(n: int, method: str | None = None) -> Callable[[Context], Records]:
    """``group/N``: the default detector; ``group_METHOD/N``: another method, with its ratio to the default."""

    def run(ctx: Context) -> Records:
        from sid.perception.groups import GroupParams, detect_groups

        people = grouping_scene(n)
        params = GroupParams() if method is None else GroupParams(method=method)
        stats = _measure_one_thread(lambda: detect_groups(people, params), ctx.settings)
        found = detect_groups(people, params)
        name = f"group/{n}" if method is None else f"group_{method}/{n}"
        extra = {} if method is None else {"ratio_to": f"group/{n}"}
        return {
            name: record(
                stats,
                groups=len(found),
                circles_found=_circles_found(found, n),
                threads=GROUPING_THREADS,
                paper_ms=PAPER_GROUP_MS.get(n),
                **extra,
            )
        }

    return run


def _circles_found(groups: Iterable[Group | BaselineGroup], n: int) -> int:
    """How many of the conversation circles of ``grouping_scene(n)`` came out exactly."""
    people = grouping_scene(n)
    circles = {tuple(p.id for p in people if _circle_of(p, n) == k) for k in {_circle_of(p, n) for p in people}}
    return len(circles & _member_sets(groups))


def _circle_of(person: Person, n: int) -> int:
    """The circle index of a person of ``grouping_scene(n)`` (ids run circle by circle, 4 per circle above 6)."""
    return 0 if n <= 6 else person.id // 4


def _bench_baseline(n: int) -> Callable[[Context], Records]:
    def run(ctx: Context) -> Records:
        from sid.perception.groups import detect_groups

        people = grouping_scene(n)
        stats = _measure_one_thread(lambda: baseline_groups(people), ctx.settings)
        found = baseline_groups(people)
        same = _member_sets(found) == _member_sets(detect_groups(people))
        return {
            f"group_baseline/{n}": record(
                stats,
                groups=len(found),
                circles_found=_circles_found(found, n),
                same_groups=same,
                threads=GROUPING_THREADS,
                ratio_to=f"group/{n}",
                paper_ms=PAPER_GROUP_MS.get(n),
            )
        }

    return run


def _dbscan_points(n: int) -> np.ndarray:
    return np.array([[p.x, p.y] for p in grouping_scene(n)])


def _bench_dbscan(n: int) -> Callable[[Context], Records]:
    def run(ctx: Context) -> Records:
        from sid.perception.cluster import dbscan_labels
        from sid.perception.groups import GroupParams

        params, points = GroupParams(), _dbscan_points(n)
        stats = _measure_one_thread(lambda: dbscan_labels(points, params.eps, params.min_samples), ctx.settings)
        return {f"dbscan/{n}": record(stats, eps=params.eps, threads=GROUPING_THREADS)}

    return run


def _bench_dbscan_sklearn(n: int) -> Callable[[Context], Records]:
    def run(ctx: Context) -> Records:
        from sklearn.cluster import DBSCAN

        from sid.perception.cluster import dbscan_labels
        from sid.perception.groups import GroupParams

        params, points = GroupParams(), _dbscan_points(n)

        def fit() -> np.ndarray:
            return DBSCAN(eps=params.eps, min_samples=params.min_samples).fit_predict(points)

        same = bool(np.array_equal(fit(), dbscan_labels(points, params.eps, params.min_samples)))
        stats = _measure_one_thread(fit, ctx.settings)
        return {
            f"dbscan_sklearn/{n}": record(
                stats, eps=params.eps, same_labels=same, threads=GROUPING_THREADS, ratio_to=f"dbscan/{n}"
            )
        }

    return run


# --- alignment, lifting, orientation ------------------------------------------------------------------------------


def _bench_align(mode: SplatMode) -> Callable[[Context], Records]:
    def run(ctx: Context) -> Records:
        from sid.perception.align import Aligner

        frame = _frames(ctx, 4)[0]
        aligner = Aligner(frame.calibration, mode)  # built once per stream, as a user does
        stats = measure(lambda: aligner(frame.depth), ctx.settings)
        kd, kc = frame.calibration.depth, frame.calibration.color
        if kd is None:  # unreachable: Aligner refuses a calibration without depth intrinsics
            raise ValueError("bench: align needs depth intrinsics; the frame's depth is registered to colour")
        filled = float(np.count_nonzero(aligner(frame.depth)) / (kc.width * kc.height))
        size = f"{kd.width}x{kd.height} -> {kc.width}x{kc.height}"
        return {f"align/{mode}": record(stats, size=size, filled_fraction=round(filled, 3))}

    return run


def _bench_sparse_depth(ctx: Context) -> Records:
    from sid.perception.align import depth_at_color_pixels

    frame = _frames(ctx, 4)[0]
    pixels = np.concatenate([d.keypoints for d in _truth_detections(frame)])
    stats = measure(lambda: depth_at_color_pixels(frame.depth, pixels, frame.calibration), ctx.settings)
    found = int(np.count_nonzero(np.isfinite(depth_at_color_pixels(frame.depth, pixels, frame.calibration))))
    return {"align/sparse_4x17": record(stats, keypoints=len(pixels), with_depth=found)}


def _bench_window_depth(ctx: Context) -> Records:
    from sid.perception.align import depth_at_color_pixels

    frame = _frames(ctx, 4)[0]
    pixels = np.concatenate([d.keypoints for d in _truth_detections(frame)])

    def lookup(search: str) -> np.ndarray:
        return depth_at_color_pixels(frame.depth, pixels, frame.calibration, search=search)  # type: ignore[arg-type]

    stats = measure(lambda: lookup("window"), ctx.settings)
    window, exact = lookup("window"), lookup("exact")
    both = np.isfinite(window) & np.isfinite(exact)
    diff_mm = float(np.median(np.abs(window - exact)[both]) * 1e3) if both.any() else None
    return {
        "align/window_4x17": record(
            stats,
            keypoints=len(pixels),
            with_depth=int(np.count_nonzero(np.isfinite(window))),
            median_diff_to_exact_mm=diff_mm,
            ratio_to="align/sparse_4x17",
        )  # fmt: skip
    }


def _bench_lift(ctx: Context) -> Records:
    from sid.perception.lifting import LiftParams, lift_people
    from sid.perception.mount import CameraMount

    frame = _frames(ctx, 4)[0]
    detections, mount, params = _truth_detections(frame), CameraMount(), LiftParams()
    stats = measure(lambda: lift_people(detections, frame.depth, frame.calibration, mount, params), ctx.settings)
    people = lift_people(detections, frame.depth, frame.calibration, mount, params)
    facing = sum(p.theta is not None for p in people)
    return {"lift/4": record(stats, people=len(people), with_facing=facing, paper_ms=PAPER_LIFT_MS[4])}


def _bench_pca(ctx: Context) -> Records:
    from sid.perception.orientation import estimate_orientations

    frame = _frames(ctx, 4)[0]
    keypoints = np.array([p.keypoints_world for p in frame.truth.people])  # (4, 17, 3)
    stats = measure(lambda: estimate_orientations(keypoints), ctx.settings)
    return {"pca/4": record(stats, people=len(keypoints))}


# --- pose models and the per-frame pipeline -----------------------------------------------------------------------


def pose_models(shared: Path) -> list[Path]:
    """The ONNX pose models in ``shared``/models, sorted by name (none when the folder is absent)."""
    folder = shared / "models"
    return sorted(folder.glob("*.onnx")) if folder.is_dir() else []


def _pose_image(ctx: Context) -> tuple[np.ndarray, str]:
    """The real five-people frame (RGB) when ../shared has it, else a rendered synthetic frame of 4 people."""

    def build() -> tuple[np.ndarray, str]:
        import cv2

        path = ctx.shared / "data" / "rgbd" / "five_people" / "color.png"
        image = cv2.imread(str(path), cv2.IMREAD_COLOR) if path.is_file() else None
        if image is not None:
            return cv2.cvtColor(image, cv2.COLOR_BGR2RGB), f"five_people/color.png {image.shape[1]}x{image.shape[0]}"
        from sid.synthetic import SyntheticCamera

        ctx.note(f"{path} is absent: pose models run on a rendered synthetic frame (S5, 1280x720)")
        frame = SyntheticCamera().capture(_frame_scene(4))
        return frame.color, "synthetic S5 1280x720"

    return ctx.cached("pose_image", build)


def _estimator(ctx: Context, path: Path) -> MoveNetMultiPose | MoveNetSinglePose | YoloPose:
    from sid.perception.pose import load_pose_estimator

    return ctx.cached(
        f"estimator/{path}",
        lambda: load_pose_estimator(path, threads=ctx.pose_threads, providers=ctx.pose_provider),
    )


def _bench_pose(path: Path) -> Callable[[Context], Records]:
    def run(ctx: Context) -> Records:
        from sid.perception.pose import MoveNetMultiPose

        estimator = _estimator(ctx, path)
        image, image_name = _pose_image(ctx)
        image_hw = image.shape[:2]
        found: list[int] = []

        def call() -> dict[str, float]:
            (pre, run, post), people = timed_call(estimator, image)
            found.append(people)
            return {"preprocess": pre / 1e6, "session_run": run / 1e6, "postprocess": post / 1e6,
                    "total": (pre + run + post) / 1e6}  # fmt: skip

        parts = measure_parts(call, ctx.settings)
        name = f"pose/{path.stem}"
        input_size = estimator.input_size
        if input_size is None and isinstance(estimator, MoveNetMultiPose):  # dynamic MultiPose: sized per image
            input_size = estimator.input_size_for(image_hw)
        out = {
            name: record(
                parts["total"],
                contract=estimator.contract,
                input_size=list(input_size) if isinstance(input_size, tuple) else input_size,
                threads=estimator.model.threads,
                provider=estimator.model.provider,
                image=image_name,
                people=found[-1],
            )
        }
        for part in ("preprocess", "session_run", "postprocess"):
            out[f"{name}/{part}"] = record(parts[part])
        return out

    return run


def real_rgbd_folders(shared: Path) -> list[Path]:
    """The one-frame folders (``color.png``, ``depth.png``, ``intrinsics.json``) under ``shared``/data/rgbd, sorted
    (none when absent): five_people and the hero frames."""
    folder = shared / "data" / "rgbd"
    return sorted(p.parent for p in folder.rglob("intrinsics.json")) if folder.is_dir() else []


def _bench_pose_int8(path: Path) -> Callable[[Context], Records]:
    """``pose_int8/STEM``: the model quantized by ``sid.perception.pose.quantize.quantize_model`` (calibrated on the
    real RGB-D frames of ../shared, else on the pose image), its ``session.run`` timed in the same calls as the
    float model's and the exact float simplification's (``.../float``, ``.../simplified``) on the same input tensor,
    in turns; ``speedup`` is the ratio of the medians, ``paired_speedup`` the median of the per-call ratios (robust
    to a load that changes during the run), ``min_speedup`` the ratio of the minimums; and
    ``sid.experiments.pose_compare`` of the INT8 model against the float one on those frames."""

    def run(ctx: Context) -> Records:
        import tempfile

        from sid.experiments.pose_compare import Criteria, compare_pipelines
        from sid.perception.pipeline import Pipeline, image_pose
        from sid.perception.pose import load_pose_estimator
        from sid.perception.pose.quantize import FLOAT_LAYERS, quantize_model, simplify_model
        from sid.sources import open_source

        frames = [(p.name, frame) for p in real_rgbd_folders(ctx.shared) for frame in open_source(str(p))]
        images = [frame.color for _, frame in frames] or [_pose_image(ctx)[0]]
        with tempfile.TemporaryDirectory(prefix="sid-bench-int8-") as work:
            int8, simplified = Path(work) / "int8.onnx", Path(work) / "simplified.onnx"
            report = quantize_model(path, int8, images)
            simplify_model(path, simplified)
            models = {"float": _estimator(ctx, path)} | {
                name: load_pose_estimator(p, threads=ctx.pose_threads, providers=ctx.pose_provider)
                for name, p in (("simplified", simplified), ("int8", int8))
            }
        image, image_name = _pose_image(ctx)
        tensor, _ = models["float"].preprocess(image)
        order = list(models.items())
        speedups: list[tuple[float, float]] = []  # per call: float / int8, simplified / int8

        def call() -> dict[str, float]:
            order.append(order.pop(0))  # each model goes first in turn: none always runs on a cache the others left
            parts = {}
            for model_name, estimator in order:
                start = time.perf_counter_ns()
                estimator.infer(tensor)
                parts[model_name] = (time.perf_counter_ns() - start) / 1e6
            speedups.append((parts["float"] / parts["int8"], parts["simplified"] / parts["int8"]))
            return parts

        parts = measure_parts(call, ctx.settings)
        paired = np.median(np.array(speedups[-parts["int8"].runs :]), axis=0)  # the timed calls, not the warm-up
        criteria = Criteria()
        rows = compare_pipelines(Pipeline(image_pose(models["float"])), Pipeline(image_pose(models["int8"])), frames)
        oks = [row.mean_oks for row in rows if row.mean_oks is not None]
        name = f"pose_int8/{path.stem}"
        int8_stats, float_stats, simplified_stats = parts["int8"], parts["float"], parts["simplified"]
        return {
            name: record(
                int8_stats,
                speedup=float_stats.median_ms / int8_stats.median_ms,
                paired_speedup=float(paired[0]),
                min_speedup=float_stats.min_ms / int8_stats.min_ms,
                paired_speedup_over_simplified=float(paired[1]),
                float_layers=FLOAT_LAYERS,
                calibration_frames=report.calibration_images,
                image=image_name,
                compared_frames=len(rows),
                lowest_mean_oks=min(oks) if oks else None,
                frames_with_other_results=sum(bool(row.problems(criteria)) for row in rows),
            ),
            f"{name}/float": record(float_stats),
            f"{name}/simplified": record(simplified_stats, speedup=float_stats.median_ms / simplified_stats.median_ms),
        }

    return run


def _pipeline_pose(ctx: Context, network_ms: list[float], session_ms: list[float]) -> tuple[Callable, str]:
    """The pose stage of the per-frame pipeline: the YOLO-pose model on the real image when ../shared has both (its
    detections are then replaced by the synthetic frame's TruthPose detections, which match the synthetic depth),
    else TruthPose alone. Each call appends to ``network_ms`` what is not the pipeline's own work (ms): the model's
    ``session.run`` and the TruthPose stand-in that replaces the model's keypoints; and to ``session_ms`` the
    ``session.run`` alone (nothing without a model)."""
    from sid.synthetic.pose import TruthPose

    truth = TruthPose()
    models = [p for p in pose_models(ctx.shared) if p.stem.startswith("yolo")]
    image, image_name = _pose_image(ctx) if models else (None, "")
    if not models or image is None or not image_name.startswith("five_people"):
        ctx.note("per-frame pipeline: no YOLO-pose model or real image in ../shared, pose = TruthPose (no network)")

        def truth_only(frame: Frame) -> list[PoseDetection]:
            start = time.perf_counter_ns()
            detections = truth(frame)
            network_ms.append((time.perf_counter_ns() - start) / 1e6)
            return detections

        return truth_only, "TruthPose"
    estimator = _estimator(ctx, models[0])

    def pose(frame: Frame) -> list[PoseDetection]:
        (_, run_ns, _), _ = timed_call(estimator, image)  # pre-processing, session.run, decoding
        start = time.perf_counter_ns()
        detections = truth(frame)
        network_ms.append((run_ns + time.perf_counter_ns() - start) / 1e6)
        session_ms.append(run_ns / 1e6)
        return detections

    return pose, f"{models[0].name} on {image_name} + TruthPose keypoints"


def _bench_frame(n: int) -> Callable[[Context], Records]:
    def run(ctx: Context) -> Records:
        from sid.perception.pipeline import Pipeline

        frames = _frames(ctx, n)
        network_ms: list[float] = []
        session_ms: list[float] = []
        pose, pose_name = _pipeline_pose(ctx, network_ms, session_ms)
        pipeline = Pipeline(pose)
        counter = iter(range(10**9))
        results = []

        shares: list[float] = []  # per call with a model: the rest of the frame / session.run

        def call() -> dict[str, float]:
            result = pipeline(frames[next(counter) % len(frames)])
            results.append(result)
            rest = result.timing_ms["total"] - network_ms[-1]
            if session_ms:
                shares.append(rest / session_ms[-1])
            return result.timing_ms | {"except_network": rest}

        parts = measure_parts(call, ctx.settings)
        timed = parts["total"].runs
        last = results[-1]
        name = f"frame/{n}"
        out = {
            name: record(
                parts["total"],
                pose=pose_name,
                people=len(last.people),
                groups=len(last.groups),
                paper_ms=PAPER_TOTAL_MS.get(n),
            )
        }
        for part, paper in (("pose", PAPER_POSE_MS), ("lift", PAPER_LIFT_MS), ("group", PAPER_GROUP_MS)):
            out[f"{name}/{part}"] = record(parts[part], paper_ms=paper.get(n))
        # Issue 28's per-frame target: everything but the network's session.run and the TruthPose stand-in
        # (pre-processing, decoding, lift, groups and whatever else the pipeline times) <= 5 % of session.run for 4
        # people, both timed in the same calls (the median of the per-call shares).
        out[f"{name}/except_network"] = record(
            parts["except_network"],
            session_run_ms=float(np.median(session_ms[-timed:])) if session_ms else None,
            share_of_session_run=float(np.median(shares[-timed:])) if shares else None,
            target_share=0.05 if n == 4 and shares else None,
        )
        return out

    return run


# --- costmap and planning -----------------------------------------------------------------------------------------


def _costmap_setup(ctx: Context) -> dict[str, Any]:
    """``sid.experiments.bench.scenes``' scene: a 20 m x 20 m map at 5 cm (400 x 400), a 720-beam scan, 3 groups of
    3-4 people,
    as two frames in which everyone moved 5 cm."""

    def build() -> dict[str, Any]:
        from costmap.grid import GridSpec
        from costmap.layers.obstacle import SCAN
        from costmap.layers.social import GROUPS, PEOPLE
        from sid.experiments.bench.scenes import bench_scene
        from sid.scenario.lidar import simulate_scan

        spec = GridSpec.from_size(0.05, (-10.0, -10.0), (20.0, 20.0))
        frames = []
        for shift in (0.0, 0.05):
            obstacles, people, groups = bench_scene(20.0, shift=shift)
            frames.append(
                {PEOPLE: people, GROUPS: groups, SCAN: simulate_scan((0.0, 0.0, 0.0), obstacles, people, beams=720)}
            )
        return {"spec": spec, "frames": frames}

    return ctx.cached("costmap", build)


def _bench_costmap_update(social: bool) -> Callable[[Context], Records]:
    def run(ctx: Context) -> Records:
        from costmap.layer import LayerInputs
        from costmap.layers.social import GROUPS, PEOPLE
        from costmap.plugins import CostmapParams, layered_costmap

        setup = _costmap_setup(ctx)
        params = CostmapParams() if social else CostmapParams().without("social")
        layered = layered_costmap(setup["spec"], params)
        frames, counter = setup["frames"], iter(range(10**9))
        stats = measure(lambda: layered.update(LayerInputs(frames[next(counter) % 2])), ctx.settings)
        name = "costmap/update" if social else "costmap/update_no_social"
        people, groups = frames[0][PEOPLE], frames[0][GROUPS]
        return {name: record(stats, cells=setup["spec"].width * setup["spec"].height, beams=720,
                             people=len(people), groups=len(groups))}  # fmt: skip

    return run


def _bench_costmap_large(ctx: Context) -> Records:
    """An 80 m x 80 m map at 5 cm (1600 x 1600): one scan builds it, then only the 3 groups move (5 cm a frame)."""
    from costmap.grid import GridSpec
    from costmap.layer import LayerInputs
    from costmap.layers.obstacle import SCAN
    from costmap.layers.social import GROUPS, PEOPLE
    from costmap.plugins import CostmapParams, layered_costmap
    from sid.experiments.bench.scenes import bench_scene
    from sid.scenario.lidar import simulate_scan

    spec = GridSpec.from_size(0.05, (-40.0, -40.0), (80.0, 80.0))
    obstacles, people, groups = bench_scene(80.0)
    layered = layered_costmap(spec, CostmapParams())
    layered.update(
        LayerInputs(
            {PEOPLE: people, GROUPS: groups, SCAN: simulate_scan((0.0, 0.0, 0.0), obstacles, people, beams=720)}
        )
    )
    moved = []
    for shift in (0.05, 0.0):
        _, moved_people, moved_groups = bench_scene(80.0, shift=shift)
        moved.append(LayerInputs({PEOPLE: moved_people, GROUPS: moved_groups}))
    counter = iter(range(10**9))
    stats = measure(lambda: layered.update(moved[next(counter) % 2]), ctx.settings)
    window = layered.update(moved[0])
    cells = 0 if window is None else (window.row1 - window.row0) * (window.col1 - window.col0)
    return {"costmap/update_1600": record(stats, cells=spec.width * spec.height, updated_cells=cells,
                                          people=len(people), groups=len(groups), target_ms=5.0)}  # fmt: skip


def _bench_inflation(ctx: Context) -> Records:
    from costmap.layer import LayerInputs
    from costmap.layers.inflation import InflationLayer, InflationParams
    from costmap.plugins import layered_costmap

    setup = _costmap_setup(ctx)
    spec = setup["spec"]
    layered = layered_costmap(spec)
    layered.update(LayerInputs(setup["frames"][0]))
    master = layered.master.costs.copy()  # walls and bodies (and their inflation, which does not change the result)
    work = master.copy()

    def inflate() -> None:
        # A new layer each call: every lethal cell is new to it, so the whole map is inflated (a layer only
        # recomputes around lethal cells that changed). write() works in place; the 160 kB copy is part of the
        # timing (docs/benchmarks.md).
        np.copyto(work, master)
        InflationLayer(spec, InflationParams(), inscribed_radius=0.25).write(work, spec.whole)

    stats = measure(inflate, ctx.settings)
    return {"costmap/inflation": record(stats, cells=master.size, method="opencv")}


def _bench_smooth(ctx: Context) -> Records:
    """``planner.smoothing.smooth`` alone on the demo task's BIT* path (seed 1, capped, so the input is fixed)."""
    from planner.facade import plan
    from planner.problem import CostField
    from planner.smoothing import smooth

    problem = _planning_task(ctx).problems["with"]
    raw = plan(problem, "bitstar", time_limit=30.0, seed=1, max_iterations=2000, simplify=False).path
    field = CostField(problem)
    stats = measure(lambda: smooth(field, raw), ctx.settings)
    return {"plan/smooth": record(stats, vertices=len(raw), raw_cost=field.path_cost(raw),
                                  cost=field.path_cost(smooth(field, raw)), target_ms=10.0)}  # fmt: skip


def _bench_render(ctx: Context) -> Records:
    """One synthetic RGB-D frame (``sid.synthetic.SyntheticCamera.capture``, shaded colour, D435i depth with noise)."""
    from sid.synthetic import SyntheticCamera

    camera, scene = SyntheticCamera(), _frame_scene(4)
    counter = iter(range(10**9))
    stats = measure(lambda: camera.capture(scene, index=next(counter), seed=0), ctx.settings)
    return {"synthetic/render": record(stats, scene=scene.name, people=len(scene.people))}


def _planning_task(ctx: Context) -> Task:
    """``sid.experiments.planner_bench.planner_task``, built once per run."""
    from sid.experiments.planner_bench import planner_task

    return ctx.cached("planning", planner_task)


def _bench_plan(planner: str) -> Callable[[Context], Records]:
    def run(ctx: Context) -> Records:
        from planner.facade import plan
        from sid.experiments.planner_bench import TARGET_BUDGET_S, bench_planner, meets_target

        task = _planning_task(ctx)
        if planner == "grid":  # deterministic: timed like any other stage
            stats = measure(lambda: plan(task.problems["with"], "grid"), ctx.settings)
            return {"plan/grid": record(stats, cost_ratio=1.0, success_rate=1.0)}
        runs, row = bench_planner(task, planner, ctx.plan_runs)
        return {
            f"plan/{planner}": record(
                Stats.of([run.result.planning_time_s * 1e3 for run in runs]),
                budget_s=TARGET_BUDGET_S,
                success_rate=row["success_rate"],
                cost_ratio=row["median_cost_ratio"],
                worst_cost_ratio=row["worst_cost_ratio"],
                meets_target=meets_target(row),
            )
        }

    return run


# --- tracking -----------------------------------------------------------------------------------------------------

TRACK_SIZES = (4, 20, 100)
TRACK_FPS = 15.0


def _bench_track(n: int) -> Callable[[Context], Records]:
    """``track/N``: one frame of the people tracker, the group tracker and the tracked-people layer (``TrackingSession``
    and ``TrackedPeopleLayer`` as ``sid.stream.SocialStream`` runs them) on ``grouping_scene(n)`` with 3 cm of fresh
    position noise and 3 degrees of facing noise per frame, every track confirmed (after 20 warm-up frames); the
    layer's grid covers the scene at 5 cm."""

    def run(ctx: Context) -> Records:
        import time

        from costmap.grid import GridSpec
        from costmap.layer import LayerInputs
        from costmap.layers.tracked import TRACKS, TrackedPeopleLayer
        from sid.perception.pipeline import FrameResult
        from sid.tracking import TrackingSession, Tracks

        scene = grouping_scene(n)
        rng = np.random.default_rng(1)
        frames = [
            [
                Person(k, p.x + rng.normal(0, 0.03), p.y + rng.normal(0, 0.03), p.theta + rng.normal(0, 0.05))
                for k, p in enumerate(scene)
                if p.theta is not None
            ]
            for _ in range(16)
        ]
        xy = np.array([[p.x, p.y] for p in scene])
        lo, hi = xy.min(axis=0) - 3.0, xy.max(axis=0) + 3.0
        spec = GridSpec.from_size(0.05, (float(lo[0]), float(lo[1])), (float(hi[0] - lo[0]), float(hi[1] - lo[1])))
        session, layer = TrackingSession(), TrackedPeopleLayer(spec)
        counter = iter(range(10**9))
        seen: dict[str, int] = {}

        def call() -> dict[str, float]:
            k = next(counter)
            result = FrameResult(k, k / TRACK_FPS, [], frames[k % len(frames)], [])
            tracked = session.update(result)
            t0 = time.perf_counter()
            layer.update(LayerInputs({TRACKS: Tracks(tracked.people, tracked.groups)}), None)
            layer_ms = (time.perf_counter() - t0) * 1e3
            seen.update(people=len(tracked.people), groups=len(tracked.groups))
            parts = {
                "people": tracked.timing_ms["track"],
                "groups": tracked.timing_ms["track_groups"],
                "layer": layer_ms,
            }
            return parts | {"total": sum(parts.values())}

        for _ in range(20):  # every track confirmed, every group reported
            call()
        parts = measure_parts(call, ctx.settings)
        name = f"track/{n}"
        out = {
            name: record(parts["total"], people=seen["people"], groups=seen["groups"], cells=spec.width * spec.height)
        }
        for part in ("people", "groups", "layer"):
            out[f"{name}/{part}"] = record(parts[part])
        return out

    return run


# --- tracking in a real-crowd-like scene --------------------------------------------------------------------------

CROWD_SIZES = (20, 60, 100)
CROWD_SETS = ("seq_eth", "seq_hotel", "zara01")
CROWD_FPS = 15.0
CROWD_WARMUP_FRAMES = 45  # 3 s: tracks confirmed, groups reported, the reference's 2 s window full
CROWD_RESOLUTION = 0.05  # m per cell of the tracked-people layer's grid
CROWD_TARGET_MS = {100: 10.0}  # issue 25: people tracker + group tracker + layer per frame


def crowd_sets(shared: Path) -> list[Path]:
    """The folders of ``CROWD_SETS`` under ``shared``/data/trajectories that hold a set (none when absent)."""
    folder = shared / "data" / "trajectories"
    return [folder / name for name in CROWD_SETS if (folder / name / "obsmat.txt").is_file()]


def _crowd_replay(ctx: Context) -> CrowdReplay:
    """``sid.experiments.bench.crowd_scene.CrowdReplay`` of the sets in ../shared, built once per run."""

    def build() -> CrowdReplay:
        from sid.experiments.bench.crowd_scene import CrowdReplay
        from sid.experiments.trajectories import load_trajectory_set

        return CrowdReplay([load_trajectory_set(path) for path in crowd_sets(ctx.shared)], rate=CROWD_FPS)

    return ctx.cached("crowd", build)


def _bench_crowd(n: int) -> Callable[[Context], Records]:
    """``crowd/N``: one frame of the people tracker and the group tracker (``TrackingSession.track``, with the
    scene's area as the view) and the tracked-people layer on that frame's tracks (a 5 cm grid covering the scene),
    on ``CrowdReplay.scene`` (N or more people of the real sets present in every frame) at 15 Hz, after
    ``CROWD_WARMUP_FRAMES`` untimed frames; ``crowd/N/coherent``: the coherent-motion reference on the same tracks,
    with its ratio to the group tracker."""

    def run(ctx: Context) -> Records:
        from costmap.grid import GridSpec
        from costmap.layer import LayerInputs
        from costmap.layers.tracked import TRACKS, TrackedPeopleLayer
        from sid.tracking import TrackingSession, Tracks, scene_view
        from sid.tracking.coherent import CoherentMotion

        s = ctx.settings
        scene = _crowd_replay(ctx).scene(n, CROWD_WARMUP_FRAMES + s.warmup + s.max_runs)
        lo, hi = scene.bounds()
        view = scene_view(np.concatenate([f.truth_positions for f in scene.frames]))
        origin, size = lo - 3.0, hi - lo + 6.0
        spec = GridSpec.from_size(
            CROWD_RESOLUTION, (float(origin[0]), float(origin[1])), (float(size[0]), float(size[1]))
        )
        session, layer, reference = TrackingSession(), TrackedPeopleLayer(spec), CoherentMotion()
        frames = iter(scene.frames)
        seen: list[tuple[int, int, int, int]] = []  # per call: people present, tracks, groups, reference's groups

        def call() -> dict[str, float]:
            frame = next(frames)
            tracked = session.track(frame.detections, frame.timestamp, view)
            t0 = time.perf_counter_ns()
            layer.update(LayerInputs({TRACKS: Tracks(tracked.people, tracked.groups)}), None)
            t1 = time.perf_counter_ns()
            coherent = reference.update(tracked.people, frame.timestamp)
            t2 = time.perf_counter_ns()
            seen.append((len(frame.truth_ids), len(tracked.people), len(tracked.groups), len(coherent)))
            parts = {"people": tracked.timing_ms["track"], "groups": tracked.timing_ms["track_groups"],
                     "layer": (t1 - t0) / 1e6}  # fmt: skip
            return parts | {"total": sum(parts.values()), "coherent": (t2 - t1) / 1e6}

        for _ in range(CROWD_WARMUP_FRAMES):
            call()
        parts = measure_parts(call, s)
        measured = np.array(seen[-parts["total"].runs :])  # the timed frames, after the warm-up calls
        present, tracks, groups, coherent = (measured[:, k] for k in range(4))
        name = f"crowd/{n}"
        out = {
            name: record(
                parts["total"],
                people=int(present.min()),
                people_max=int(present.max()),
                tracks=int(np.median(tracks)),
                groups=int(np.median(groups)),
                copies=len(scene.copies),
                cells=spec.width * spec.height,
                target_ms=CROWD_TARGET_MS.get(n),
            )
        }
        for part in ("people", "groups", "layer"):
            out[f"{name}/{part}"] = record(parts[part])
        out[f"{name}/coherent"] = record(parts["coherent"], groups=int(np.median(coherent)), ratio_to=f"{name}/groups")
        return out

    return run


# --- the suite ----------------------------------------------------------------------------------------------------


def benchmarks(ctx: Context) -> list[Benchmark]:
    """Every benchmark of ``sid bench`` in report order: pose benchmarks for the models found under ``ctx.shared``
    and crowd benchmarks for its trajectory sets (a note when there are none), planning benchmarks for every
    registered planner."""
    try:
        from planner.facade import PLANNERS as planners
    except ImportError as exc:  # OMPL missing: the rest of the suite still runs
        ctx.note(f"planning benchmarks skipped: the planner cannot be imported ({exc})")
        planners = ()
    models = pose_models(ctx.shared)
    if not models:
        ctx.note(f"pose benchmarks skipped: no .onnx model in {ctx.shared / 'models'}")
    items = [
        Benchmark(f"group/{n}", f"sid.perception.groups.detect_groups (default: ospace), {n} people", _bench_group(n))
        for n in GROUP_SIZES
    ]
    items += [
        Benchmark(
            f"group_gcff/{n}",
            f"detect_groups, method gcff (graph cuts, the literature's reference), {n} people",
            _bench_group(n, "gcff"),
            needs=(f"group/{n}",),
        )
        for n in GROUP_SIZES
    ]
    items += [
        Benchmark(
            f"group_rays/{n}", f"detect_groups, method rays, {n} people", _bench_group(n, "rays"), needs=(f"group/{n}",)
        )
        for n in GROUP_SIZES
    ]
    items += [
        Benchmark(
            f"group_paper/{n}",
            f"detect_groups, method paper (Algorithm 1), {n} people",
            _bench_group(n, "paper"),
            needs=(f"group/{n}",),
        )
        for n in GROUP_SIZES
        if n <= PAPER_GROUP_MAX
    ]
    items += [
        Benchmark(
            f"group_baseline/{n}",
            f"authors' approach (sid.experiments.bench.baseline), {n} people",
            _bench_baseline(n),
            needs=(f"group/{n}",),
        )  # fmt: skip
        for n in GROUP_SIZES
        if n <= PAPER_GROUP_MAX
    ]
    for n in DBSCAN_SIZES:
        items.append(Benchmark(f"dbscan/{n}", f"sid.perception.cluster.dbscan_labels, {n} points", _bench_dbscan(n)))
        items.append(
            Benchmark(
                f"dbscan_sklearn/{n}", f"sklearn DBSCAN, {n} points", _bench_dbscan_sklearn(n), needs=(f"dbscan/{n}",)
            )  # fmt: skip
        )
    items += [
        Benchmark(f"align/{mode}", f"Aligner ({mode} splat), full frame", _bench_align(mode)) for mode in ALIGN_MODES
    ]
    items += [
        Benchmark("align/sparse_4x17", "depth_at_color_pixels, 4 x 17 keypoints", _bench_sparse_depth),
        Benchmark(
            "align/window_4x17",
            "depth_at_color_pixels(search='window'), 4 x 17 keypoints",
            _bench_window_depth,
            needs=("align/sparse_4x17",),
        ),  # fmt: skip
        Benchmark("lift/4", "lift_people (keypoint depth, 3D, position, PCA facing), 4 people", _bench_lift),
        Benchmark("pca/4", "estimate_orientations (PCA facing), 4 people at once", _bench_pca),
    ]
    items += [Benchmark(f"pose/{p.stem}", f"pose model {p.name}", _bench_pose(p)) for p in models]
    if models and importlib.util.find_spec("onnx") is None:
        ctx.note(f"INT8 pose benchmarks skipped: quantizing needs the onnx package ({install_hint('quantize')})")
    elif models:
        items += [
            Benchmark(
                f"pose_int8/{p.stem}",
                f"{p.name} quantized to INT8 (sid model quantize): session.run beside the float model's",
                _bench_pose_int8(p),
            )
            for p in models
        ]
    items += [Benchmark(f"frame/{n}", f"Pipeline per frame, {n} people", _bench_frame(n)) for n in FRAME_SIZES]
    items += [
        Benchmark("costmap/update", "LayeredCostmap.update, 400x400, 720 beams, 3 groups", _bench_costmap_update(True)),
        Benchmark("costmap/update_no_social", "the same without the social layer", _bench_costmap_update(False)),
        Benchmark("costmap/update_1600", "LayeredCostmap.update, 1600x1600, 3 moving groups", _bench_costmap_large),
        Benchmark("costmap/inflation", "InflationLayer.write alone, whole 400x400 map", _bench_inflation),
    ]
    items += [
        Benchmark(f"track/{n}", f"people + group tracking and the tracked-people layer, {n} people", _bench_track(n))
        for n in TRACK_SIZES
    ]
    sets = crowd_sets(ctx.shared)
    if not sets:
        folder = ctx.shared / "data" / "trajectories"
        ctx.note(f"crowd benchmarks skipped: no trajectory set ({', '.join(CROWD_SETS)}) in {folder}")
    items += [
        Benchmark(
            f"crowd/{n}",
            f"people + group trackers + tracked-people layer, and the coherent-motion reference, on {n}+ people of "
            f"real trajectories ({', '.join(p.name for p in sets)}: disjoint stretches side by side, loners trimmed)",
            _bench_crowd(n),
        )
        for n in CROWD_SIZES
        if sets
    ]
    items += [Benchmark(f"plan/{p}", f"planner {p} on the demo scenario", _bench_plan(p)) for p in planners]
    if planners:
        items.append(Benchmark("plan/smooth", "planner.smoothing.smooth on a BIT* path", _bench_smooth))
    items.append(Benchmark("synthetic/render", "SyntheticCamera.capture, 4 people", _bench_render))
    return items

"""``track/N`` and ``crowd/N``: the people tracker, the group tracker and the tracked-people layer per frame, on
conversation circles and on real pedestrian crowds (beside the coherent-motion reference)."""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from sid.experiments.bench.runner import measure_parts
from sid.experiments.bench.stages.core import (
    Benchmark,
    Context,
    Records,
    record,
)
from sid.experiments.bench.stages.inputs import grouping_scene
from sid.perception.people import Person

if TYPE_CHECKING:
    from sid.experiments.bench.crowd_scene import CrowdReplay

__all__ = [
    "CROWD_FPS",
    "CROWD_RESOLUTION",
    "CROWD_SETS",
    "CROWD_SIZES",
    "CROWD_TARGET_MS",
    "CROWD_WARMUP_FRAMES",
    "TRACK_FPS",
    "TRACK_SIZES",
    "crowd_benchmarks",
    "crowd_sets",
    "track_benchmarks",
]

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
        from sid.tracking import TrackingSession

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
            layer.update(LayerInputs({TRACKS: tracked.all_tracks()}), None)
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
        from sid.tracking import TrackingSession, scene_view
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
            drawn = tracked.all_tracks()
            layer.update(LayerInputs({TRACKS: drawn}), None)
            t1 = time.perf_counter_ns()
            coherent = reference.update(list(drawn.people), frame.timestamp)
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


def track_benchmarks() -> list[Benchmark]:
    """One tracked frame for each of ``TRACK_SIZES`` people in conversation circles."""
    return [
        Benchmark(f"track/{n}", f"people + group tracking and the tracked-people layer, {n} people", _bench_track(n))
        for n in TRACK_SIZES
    ]


def crowd_benchmarks(ctx: Context) -> list[Benchmark]:
    """One tracked frame of a real crowd for each of ``CROWD_SIZES`` people (a note when ../shared has no set)."""
    sets = crowd_sets(ctx.shared)
    if not sets:
        folder = ctx.shared / "data" / "trajectories"
        ctx.note(f"crowd benchmarks skipped: no trajectory set ({', '.join(CROWD_SETS)}) in {folder}")
    return [
        Benchmark(
            f"crowd/{n}",
            f"people + group trackers + tracked-people layer, and the coherent-motion reference, on {n}+ people of "
            f"real trajectories ({', '.join(p.name for p in sets)}: disjoint stretches side by side, loners trimmed)",
            _bench_crowd(n),
        )
        for n in CROWD_SIZES
        if sets
    ]

"""Synthetic RGB-D source: rendered people with D435-like noise and ground truth on every frame.

>>> for frame in SyntheticSource("S3", frames=10, seed=0):
...     frame.depth, frame.truth.people[0].x

Specs (``sid detect --source synthetic:SPEC``): a layout name (``S1``..``S5``, see ``sid.synthetic.layouts``), a
built-in sequence name (``crossing_walkers``, ``drive_past_group``, ``walking_pairs``, ``file_behind_group``,
``close_crossing``, see ``sid.synthetic.sequence``), or the path of a scene file (static, see ``sid.synthetic.scene``)
or of a costmap scenario file (JSON or YAML; people and robot may move, see docs/scenario.md). Frames of a scenario
carry the robot's pose, so the pipeline reports in the scenario's map frame; frame ``i`` shows time ``i / fps`` (s).
Each frame draws fresh depth and keypoint noise, reproducibly from ``seed`` and the frame index.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

from sid.checks import check_whole
from sid.errors import InputTypeError
from sid.perception.frame import Frame
from sid.scenario.loader import Scenario
from sid.sources import SourceError
from sid.synthetic.layouts import LAYOUTS, layout
from sid.synthetic.noise import DepthNoise, KeypointNoise
from sid.synthetic.scene import Scene
from sid.synthetic.sensor import SyntheticCamera
from sid.synthetic.sequence import SEQUENCES, SyntheticSequence, builtin_sequence, load_scene_file

__all__ = ["DEFAULT_FRAMES", "PREFIX", "SyntheticSource", "scene_from_spec", "synthetic_source"]

PREFIX = "synthetic:"
DEFAULT_FRAMES = 30  # frames of a static scene when none are asked for


def scene_from_spec(spec: str) -> Scene | SyntheticSequence:
    """A layout name (S1-S5, case-insensitive), a built-in sequence name or a scene/scenario file path, with or
    without ``synthetic:``.

    Raises ``SourceError`` naming the problem (unknown name, missing or malformed file)."""
    name = spec[len(PREFIX) :] if spec.startswith(PREFIX) else spec
    known = f"layouts {', '.join(LAYOUTS)}; sequences {', '.join(SEQUENCES)}"
    if not name:
        raise SourceError(f"synthetic source: empty spec; use synthetic:NAME ({known}) or synthetic:FILE")
    if name.upper() in LAYOUTS:
        return layout(name)
    if name in SEQUENCES:
        return builtin_sequence(name)
    path = Path(name)
    if not path.is_file():
        raise SourceError(f"synthetic source: {name!r} is neither a built-in scene ({known}) nor an existing file")
    try:
        return load_scene_file(path)
    except ValueError as exc:
        raise SourceError(f"synthetic source: {exc}") from None


class SyntheticSource:
    """Iterable of ``frames`` synthetic ``Frame``s of one scene, ground truth in ``frame.truth``.

    scene_or_spec: a static ``Scene``, a moving ``SyntheticSequence``, a ``sid.scenario.loader.Scenario`` (as a
    ``SyntheticSequence``) or a spec string (see ``scene_from_spec``). frames: how many (None: ``DEFAULT_FRAMES`` of a
    static scene, or a sequence until everyone has stopped, ``duration * fps + 1``). seed: noise seed. noise /
    keypoint_noise: depth and 2D keypoint noise (defaults: ``DepthNoise()``, ``KeypointNoise()``;
    ``DepthNoise.exact()`` and ``KeypointNoise(0, 0)`` for perfect data). Further keyword options go to
    ``SyntheticCamera`` (``registered``, ``calibration``, ``shaded_color``, ``occlusion_margin``,
    ``self_occlusion_margin``, ``fps``, ``group_params``).
    """

    def __init__(
        self,
        scene_or_spec: Scene | SyntheticSequence | str | Any,
        frames: int | None = None,
        seed: int = 0,
        noise: DepthNoise | None = None,
        keypoint_noise: KeypointNoise | None = None,
        **camera_options: Any,
    ):
        self.scene: Scene | SyntheticSequence
        if isinstance(scene_or_spec, (Scene, SyntheticSequence)):
            self.scene = scene_or_spec
        elif isinstance(scene_or_spec, (str, Path)):
            self.scene = scene_from_spec(str(scene_or_spec))
        elif isinstance(scene_or_spec, Scenario):
            self.scene = SyntheticSequence.from_scenario(scene_or_spec)
        else:
            raise InputTypeError(
                "synthetic source: expected a Scene, a SyntheticSequence, a spec string or a scenario, got "
                f"{type(scene_or_spec).__name__}"
            )
        self.seed = int(seed)
        self.camera = SyntheticCamera(noise=noise, keypoint_noise=keypoint_noise, **camera_options)
        if frames is None:
            duration = self.scene.duration if isinstance(self.scene, SyntheticSequence) else 0.0
            frames = round(duration * self.camera.fps) + 1 if duration > 0 else DEFAULT_FRAMES
        check_whole("synthetic source", "frames", frames, low=0)
        self.frames = int(frames)

    def __len__(self) -> int:
        return self.frames

    def __iter__(self) -> Iterator[Frame]:
        for index in range(self.frames):
            yield self.camera.capture(self.scene, index, self.seed)

    def __getitem__(self, index: int) -> Frame:
        """Frame ``index`` alone (the same as the one iteration yields)."""
        if not 0 <= index < self.frames:
            raise IndexError(f"synthetic source: frame {index} out of range 0..{self.frames - 1}")
        return self.camera.capture(self.scene, index, self.seed)


def synthetic_source(spec: str, **options: Any) -> SyntheticSource:
    """``SyntheticSource`` from a ``synthetic:SPEC`` string (``options`` as for ``SyntheticSource``)."""
    return SyntheticSource(scene_from_spec(spec), **options)

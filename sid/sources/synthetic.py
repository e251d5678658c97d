"""Synthetic RGB-D source: rendered people with D435-like noise and ground truth on every frame.

>>> for frame in SyntheticSource("S3", frames=10, seed=0):
...     frame.depth, frame.truth.people[0].x

Specs (``sid detect --source synthetic:SPEC``): a layout name (``S1``..``S5``, see ``sid.synthetic.layouts``) or
the path of a scene / costmap scenario file (JSON or YAML, see ``sid.synthetic.scene``). Frames show a static
scene; each frame draws fresh depth and keypoint noise, reproducibly from ``seed`` and the frame index.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

from sid.perception.frame import Frame
from sid.sources import SourceError
from sid.synthetic.layouts import LAYOUTS, layout
from sid.synthetic.noise import DepthNoise, KeypointNoise
from sid.synthetic.scene import Scene
from sid.synthetic.sensor import SyntheticCamera

PREFIX = "synthetic:"


def scene_from_spec(spec: str) -> Scene:
    """A layout name (S1-S5, case-insensitive) or a scene/scenario file path, with or without ``synthetic:``.

    Raises ``SourceError`` naming the problem (unknown layout, missing or malformed file)."""
    name = spec[len(PREFIX) :] if spec.startswith(PREFIX) else spec
    if not name:
        raise SourceError(
            f"synthetic source: empty spec; use synthetic:LAYOUT ({', '.join(LAYOUTS)}) or synthetic:FILE"
        )
    if name.upper() in LAYOUTS:
        return layout(name)
    path = Path(name)
    if not path.is_file():
        raise SourceError(
            f"synthetic source: {name!r} is neither a layout ({', '.join(LAYOUTS)}) nor an existing scene file"
        )
    try:
        return Scene.from_file(path)
    except ValueError as exc:
        raise SourceError(f"synthetic source: {exc}") from None


class SyntheticSource:
    """Iterable of ``frames`` synthetic ``Frame``s of one scene, ground truth in ``frame.truth``.

    scene_or_spec: a ``Scene``, a ``sid.scenario.loader.Scenario`` (seen from the robot's start pose, see
    ``Scene.from_scenario``) or a spec string (see ``scene_from_spec``). seed: noise seed. noise / keypoint_noise:
    depth and 2D keypoint noise (defaults: ``DepthNoise()``, ``KeypointNoise()``; ``DepthNoise.exact()`` and
    ``KeypointNoise(0, 0)`` for perfect data). Further keyword options go to ``SyntheticCamera`` (``registered``,
    ``calibration``, ``shaded_color``, ``occlusion_margin``, ``self_occlusion_margin``, ``fps``, ``group_params``).
    """

    def __init__(
        self,
        scene_or_spec: Scene | str | Any,
        frames: int = 30,
        seed: int = 0,
        noise: DepthNoise | None = None,
        keypoint_noise: KeypointNoise | None = None,
        **camera_options: Any,
    ):
        if isinstance(scene_or_spec, Scene):
            self.scene = scene_or_spec
        elif isinstance(scene_or_spec, (str, Path)):
            self.scene = scene_from_spec(str(scene_or_spec))
        elif hasattr(scene_or_spec, "robot") and isinstance(getattr(scene_or_spec, "people", None), list):
            self.scene = Scene.from_scenario(scene_or_spec)
        else:
            raise TypeError(
                f"synthetic source: expected a Scene, a spec string or a scenario, got {type(scene_or_spec).__name__}"
            )
        if int(frames) != frames or frames < 0:
            raise ValueError(f"synthetic source: frames must be a whole number >= 0, got {frames}")
        self.frames = int(frames)
        self.seed = int(seed)
        self.camera = SyntheticCamera(noise=noise, keypoint_noise=keypoint_noise, **camera_options)

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

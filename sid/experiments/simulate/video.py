"""Pictures and videos of a run: one frame per step.

A frame (BGR uint8) is ``costmap.render.render_costmap`` of the robot's costmap at that step (the costs, the known
obstacles' outlines, the LiDAR hits, the people and groups the robot perceives, the camera's field of view), with the
planned path (purple), the driven path (dark green), the robot's disc and heading, the goal, the true people as
grey rings, the time in the title, and the camera's colour image in a column on the right.

``VideoWriter`` writes MP4 (H.264 through imageio-ffmpeg's bundled ffmpeg) and, on request, a GIF (Pillow) of every
``gif_every``-th frame at half size.
"""

from __future__ import annotations

import math
from collections.abc import Generator
from pathlib import Path
from types import TracebackType

import cv2
import numpy as np

from costmap.render import CameraView, default_scale, render_costmap, world_to_image
from planner.render import WITH_COLOUR, PathStyle, draw_path
from sid.experiments.simulate.loop import StepView
from sid.experiments.simulate.perception import FIELD_OF_VIEW
from sid.experiments.simulate.world import SimWorld
from sid.scenario.obstacles import outline

DRIVEN = PathStyle("driven", (40, 110, 0))
PLANNED = PathStyle("planned", WITH_COLOUR)
ROBOT = (40, 110, 0)
TRUE_PERSON = (130, 130, 130)
GOAL = (30, 30, 220)
INSET_WIDTH = 320


def frame_picture(view: StepView, world: SimWorld, driven: np.ndarray, title: str) -> np.ndarray:
    """The BGR picture of one step (see the module docstring); ``driven``: the trajectory so far (N, 2)."""
    spec = view.costmap.spec
    scale = default_scale(spec)
    robot = view.robot
    camera = CameraView(robot.x, robot.y, robot.yaw, FIELD_OF_VIEW) if view.image is not None else None
    img = render_costmap(
        view.costmap,
        view.seen,
        view.groups,
        scale=scale,
        scan=view.scan,
        title=title,
        camera=camera,
        outlines=[outline(ob) for ob in world.scenario.obstacles],
    )
    px_per_m = scale / spec.resolution
    for person in view.people:
        u, v = world_to_image([[person.x, person.y]], spec, scale)[0]
        r = world.scenario.lidar.body_radius * px_per_m
        cv2.circle(img, (int(u), int(v)), int(round(r)), TRUE_PERSON, 2, cv2.LINE_AA)
    if view.path is not None:
        draw_path(img, view.path, spec, scale, PLANNED, 2)
    draw_path(img, driven, spec, scale, DRIVEN, 2)
    goal = world.scenario.robot.goal
    gu, gv = world_to_image([goal[:2]], spec, scale)[0]
    cv2.drawMarker(img, (int(gu), int(gv)), GOAL, cv2.MARKER_TILTED_CROSS, 16, 3, cv2.LINE_AA)
    (u, v), (nu, nv) = world_to_image(
        [[robot.x, robot.y], [robot.x + world.settings.limits.radius * math.cos(robot.yaw),
                              robot.y + world.settings.limits.radius * math.sin(robot.yaw)]], spec, scale
    )  # fmt: skip
    cv2.circle(img, (int(u), int(v)), int(round(world.settings.limits.radius * px_per_m)), ROBOT, 2, cv2.LINE_AA)
    cv2.line(img, (int(u), int(v)), (int(nu), int(nv)), ROBOT, 2, cv2.LINE_AA)
    strip = np.full((img.shape[0], INSET_WIDTH + 16, 3), 255, dtype=np.uint8)
    if view.image is not None:
        inset = cv2.cvtColor(view.image, cv2.COLOR_RGB2BGR)
        height = min(int(round(inset.shape[0] * INSET_WIDTH / inset.shape[1])), img.shape[0] - 40)
        strip[34 : 34 + height, 8 : 8 + INSET_WIDTH] = cv2.resize(
            inset, (INSET_WIDTH, height), interpolation=cv2.INTER_AREA
        )
        cv2.rectangle(strip, (7, 33), (8 + INSET_WIDTH, 34 + height), (40, 40, 40), 1)
    caption = "the robot's camera" if view.image is not None else "no camera image (no recognition, or exact people)"
    cv2.putText(strip, caption, (8, 26), cv2.FONT_HERSHEY_SIMPLEX, 0.5, (40, 40, 40), 1, cv2.LINE_AA)
    return np.hstack([img, strip])
    return img


class VideoWriter:
    """Frames (BGR, all the same size) to ``mp4`` (imageio-ffmpeg) and optionally ``gif`` (Pillow); a context
    manager that finishes both files on exit."""

    def __init__(self, mp4: Path | None, fps: float, gif: Path | None = None, gif_every: int = 2) -> None:
        self.mp4, self.gif, self.fps, self.gif_every = mp4, gif, float(fps), max(1, int(gif_every))
        self._writer: Generator[None, np.ndarray | None, None] | None = None
        self._size = (0, 0)
        self._gif_frames: list[np.ndarray] = []
        self._count = 0

    def __enter__(self) -> VideoWriter:
        return self

    def add(self, bgr: np.ndarray) -> None:
        rgb = np.ascontiguousarray(cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB))
        if self.mp4 is not None:
            if self._writer is None:
                import imageio_ffmpeg

                # H.264 in yuv420p needs even sizes: pad by one pixel where needed.
                self._size = (rgb.shape[1] + rgb.shape[1] % 2, rgb.shape[0] + rgb.shape[0] % 2)
                writer = imageio_ffmpeg.write_frames(
                    str(self.mp4), self._size, fps=self.fps, macro_block_size=1, quality=7
                )
                writer.send(None)
                self._writer = writer
            padded = np.full((self._size[1], self._size[0], 3), 255, dtype=np.uint8)
            padded[: rgb.shape[0], : rgb.shape[1]] = rgb
            self._writer.send(padded)
        if self.gif is not None and self._count % self.gif_every == 0:
            half = cv2.resize(rgb, (rgb.shape[1] // 2, rgb.shape[0] // 2), interpolation=cv2.INTER_AREA)
            self._gif_frames.append(half)
        self._count += 1

    def close(self) -> None:
        if self._writer is not None:
            self._writer.close()
            self._writer = None
        if self.gif is not None and self._gif_frames:
            from PIL import Image

            images = [Image.fromarray(f).quantize(colors=128) for f in self._gif_frames]
            duration = int(round(1000 * self.gif_every / self.fps))
            images[0].save(self.gif, save_all=True, append_images=images[1:], duration=duration, loop=0)
            self._gif_frames = []

    def __exit__(
        self, kind: type[BaseException] | None, value: BaseException | None, traceback: TracebackType | None
    ) -> None:
        self.close()

"""Pictures and videos of a run: one frame per step.

A frame (BGR uint8) is ``costmap.render.render_costmap`` of the robot's costmap at that step (the costs, the known
obstacles' outlines, the LiDAR hits, the people and groups the robot perceives, the camera's field of view), with the
planned path (purple), the driven path (navy), the robot's disc and heading (navy), the goal, the true people as
grey rings, a legend of all of it, the time in the title, and the camera's colour image in a column on the right.

``VideoWriter`` writes MP4 (MPEG-4 Part 2, OpenCV's ``mp4v``: the FFmpeg inside opencv-python has no H.264 encoder;
VLC, QuickTime and the Windows players show it, web browsers do not) and, on request, a GIF (Pillow) of every
``gif_every``-th frame at full size, for web pages.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from types import TracebackType

import cv2
import numpy as np

from costmap.grid import GridSpec
from costmap.layers.social import SocialParams
from costmap.render import (
    LEGEND,
    LEGEND_ROW,
    MARGIN_BOTTOM,
    MARGIN_LEFT,
    MARGIN_TOP,
    MAX_GROUP_ENTRIES,
    CameraView,
    Extra,
    default_scale,
    render_costmap,
    world_to_image,
)
from sid.experiments.path_render import WITH_COLOUR, PathStyle, path_extra
from sid.experiments.simulate.loop import StepView
from sid.experiments.simulate.perception import FIELD_OF_VIEW
from sid.experiments.simulate.world import SimWorld
from sid.scenario.obstacles import outline

__all__ = [
    "DRIVEN",
    "GOAL",
    "INSET_WIDTH",
    "LEGEND_WIDTH",
    "PLANNED",
    "ROBOT",
    "TRUE_PERSON",
    "VideoWriter",
    "frame_picture",
    "MP4_CODEC",
]

ROBOT = (90, 40, 0)  # BGR: navy, the robot and its driven path
DRIVEN = PathStyle("driven path", ROBOT)
PLANNED = PathStyle("planned path", WITH_COLOUR)
TRUE_PERSON = (130, 130, 130)
GOAL = (30, 30, 220)
INSET_WIDTH = 320
LEGEND_WIDTH = 260  # px right of the map: the colour scale and the legend


def _true_person_swatch(img: np.ndarray, u: int, v: int) -> None:
    cv2.circle(img, (u, v), 6, TRUE_PERSON, 2, cv2.LINE_AA)


def _goal_swatch(img: np.ndarray, u: int, v: int) -> None:
    cv2.drawMarker(img, (u, v), GOAL, cv2.MARKER_TILTED_CROSS, 12, 2, cv2.LINE_AA)


def _robot_swatch(img: np.ndarray, u: int, v: int) -> None:
    cv2.circle(img, (u, v), 7, ROBOT, 2, cv2.LINE_AA)
    cv2.line(img, (u, v), (u + 7, v), ROBOT, 2, cv2.LINE_AA)


def _robot_extras(view: StepView, world: SimWorld, driven: np.ndarray) -> list[Extra]:
    """What a step's picture draws over the costmap, each with its legend entry: the true people, the planned and
    driven paths, the goal and the robot."""
    radius, body = world.settings.limits.radius, world.scenario.lidar.body_radius
    robot, goal = view.robot, world.scenario.robot.goal

    def ring(centre: tuple[float, float], r_m: float, colour: tuple[int, int, int]) -> Callable[..., None]:
        def draw(img: np.ndarray, spec: GridSpec, scale: int) -> None:
            u, v = world_to_image([centre], spec, scale)[0]
            cv2.circle(img, (int(u), int(v)), int(round(r_m * scale / spec.resolution)), colour, 2, cv2.LINE_AA)

        return draw

    def true_people(img: np.ndarray, spec: GridSpec, scale: int) -> None:
        for person in view.people:
            ring((person.x, person.y), body, TRUE_PERSON)(img, spec, scale)

    def robot_disc(img: np.ndarray, spec: GridSpec, scale: int) -> None:
        ring((robot.x, robot.y), radius, ROBOT)(img, spec, scale)
        nose = (robot.x + radius * math.cos(robot.yaw), robot.y + radius * math.sin(robot.yaw))
        (u, v), (nu, nv) = world_to_image([[robot.x, robot.y], nose], spec, scale).astype(int)
        cv2.line(img, (int(u), int(v)), (int(nu), int(nv)), ROBOT, 2, cv2.LINE_AA)

    def goal_cross(img: np.ndarray, spec: GridSpec, scale: int) -> None:
        gu, gv = world_to_image([goal[:2]], spec, scale)[0]
        cv2.drawMarker(img, (int(gu), int(gv)), GOAL, cv2.MARKER_TILTED_CROSS, 16, 3, cv2.LINE_AA)

    extras = []
    if view.people:
        extras.append(Extra("true people (simulation)", _true_person_swatch, true_people))
    if view.path is not None:
        extras.append(path_extra(view.path, PLANNED, 2))
    if len(driven) >= 2:
        extras.append(path_extra(driven, DRIVEN, 2))
    return [*extras, Extra("goal", _goal_swatch, goal_cross), Extra("robot, heading", _robot_swatch, robot_disc)]


def _map_picture_size(spec: GridSpec, people: int) -> tuple[int, int]:
    """Height and width (px) of every step's costmap picture in a run: room for the map and for the longest legend
    the run can have (every entry, one per possible group), so that the video's frames are all one size."""
    groups = people // 2
    rows = 1 + min(groups, MAX_GROUP_ENTRIES) + (groups > MAX_GROUP_ENTRIES) + len(LEGEND) - 2 + 5  # no robot task
    scale = default_scale(spec)
    height = max(MARGIN_TOP + spec.height * scale + MARGIN_BOTTOM, MARGIN_TOP + 10 + 224 + 74 + LEGEND_ROW * rows)
    return height, MARGIN_LEFT + spec.width * scale + LEGEND_WIDTH


def _pad(img: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    """``img`` on a white canvas of ``size`` (h, w), top-left aligned (cut where it is larger)."""
    canvas = np.full((*size, 3), 255, dtype=np.uint8)
    h, w = min(size[0], img.shape[0]), min(size[1], img.shape[1])
    canvas[:h, :w] = img[:h, :w]
    return canvas


def frame_picture(view: StepView, world: SimWorld, driven: np.ndarray, title: str) -> np.ndarray:
    """The BGR picture of one step (see the module docstring); ``driven``: the trajectory so far (N, 2)."""
    robot = view.robot
    camera = CameraView(robot.x, robot.y, robot.yaw, FIELD_OF_VIEW) if view.image is not None else None
    img = render_costmap(
        view.costmap,
        view.seen,
        view.groups,
        scale=default_scale(view.costmap.spec),
        scan=view.scan,
        title=title,
        camera=camera,
        outlines=[outline(ob) for ob in world.scenario.obstacles],
        zone_margin=SocialParams().group_margin,  # the tracked-people layer's (costmap.layers.tracked)
        extras=_robot_extras(view, world, driven),
    )
    img = _pad(img, _map_picture_size(view.costmap.spec, len(world.scenario.people)))
    strip = np.full((img.shape[0], INSET_WIDTH + 16, 3), 255, dtype=np.uint8)
    if view.image is not None:
        inset = cv2.cvtColor(view.image, cv2.COLOR_RGB2BGR)
        height = min(int(round(inset.shape[0] * INSET_WIDTH / inset.shape[1])), img.shape[0] - 40)
        strip[34 : 34 + height, 8 : 8 + INSET_WIDTH] = cv2.resize(
            inset, (INSET_WIDTH, height), interpolation=cv2.INTER_AREA
        )
        cv2.rectangle(strip, (7, 33), (8 + INSET_WIDTH, 34 + height), (40, 40, 40), 1)
    captions = (
        ["the robot's camera"] if view.image is not None else ["no camera image:", "no recognition, or exact people"]
    )
    for row, caption in enumerate(captions):
        cv2.putText(strip, caption, (8, 26 + 22 * row), cv2.FONT_HERSHEY_SIMPLEX, 0.5, (40, 40, 40), 1, cv2.LINE_AA)
    return np.hstack([img, strip])


MP4_CODEC = "mp4v"
"""OpenCV's four-character code of the MP4 video codec (MPEG-4 Part 2)."""


class VideoWriter:
    """Frames (BGR, all the same size) to ``mp4`` (OpenCV) and optionally ``gif`` (Pillow); a context manager that
    finishes both files on exit. OSError when OpenCV cannot write the MP4 file."""

    def __init__(self, mp4: Path | None, fps: float, gif: Path | None = None, gif_every: int = 2) -> None:
        self.mp4, self.gif, self.fps, self.gif_every = mp4, gif, float(fps), max(1, int(gif_every))
        self._writer: cv2.VideoWriter | None = None
        self._size = (0, 0)
        self._gif_frames: list[np.ndarray] = []
        self._count = 0

    def __enter__(self) -> VideoWriter:
        return self

    def add(self, bgr: np.ndarray) -> None:
        if self.mp4 is not None:
            if self._writer is None:
                # 4:2:0 video needs even sizes: pad by one pixel where needed.
                self._size = (bgr.shape[1] + bgr.shape[1] % 2, bgr.shape[0] + bgr.shape[0] % 2)
                self._writer = cv2.VideoWriter(str(self.mp4), cv2.VideoWriter.fourcc(*MP4_CODEC), self.fps, self._size)
                if not self._writer.isOpened():
                    self._writer = None
                    raise OSError(f"cannot write {self.mp4}: OpenCV found no {MP4_CODEC} video encoder")
            padded = np.full((self._size[1], self._size[0], 3), 255, dtype=np.uint8)
            padded[: bgr.shape[0], : bgr.shape[1]] = bgr
            self._writer.write(padded)
        if self.gif is not None and self._count % self.gif_every == 0:
            self._gif_frames.append(cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB))  # full size: as legible as the video
        self._count += 1

    def close(self) -> None:
        if self._writer is not None:
            self._writer.release()
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

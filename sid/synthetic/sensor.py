"""A virtual RealSense D435i: renders a scene into an RGB-D ``Frame`` with its ground truth attached.

Scenes: a static ``Scene`` (people in the robot's frame, base_footprint; frames carry no robot pose) or a moving
``SyntheticSequence`` (people and robot in the map frame; frame ``index`` shows time ``index / fps`` and carries the
robot's pose). Ground truth is in the same frame as the scene (``FrameTruth.frame_id``).

Cameras: the colour camera's optical frame is the one the mount places on the robot (the frame the pipeline
lifts keypoints from); the depth camera sits ``depth_to_color`` away from it (p_color = R p_depth + t). Defaults are
typical D435i values: colour 1280x720 with fx = fy = 910 px, depth 848x480 with fx = fy = 420 px, the depth
camera 15 mm along +x of the colour optical frame, i.e. to the colour camera's right looking along its view (depth ->
colour translation +15 mm along x).

Per frame: exact depth from a ray caster (``render``), then D435-like noise (``noise.DepthNoise``); truth
keypoints are the skeleton's joints projected with the colour intrinsics, flagged invisible when outside the
colour image or hidden behind another person, flagged self-occluded when deep behind the person's own body (a face
seen from behind, the far shoulder of someone in profile), and observed with ``noise.KeypointNoise`` (pixel noise,
dropped keypoints). The exact render of the people as the camera sees them is kept and reused while they (and the robot)
stand still; each frame draws its own noise from ``numpy.random.default_rng([seed, index])``, so any frame can be
regenerated alone.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from sid.checks import check_number, check_numbers
from sid.errors import InputError
from sid.perception.camera import Calibration, Extrinsics, Intrinsics, project
from sid.perception.frame import Frame
from sid.perception.groups import GroupParams
from sid.perception.keypoints import NUM_KEYPOINTS
from sid.perception.mount import CameraMount
from sid.perception.robot_pose import BASE_FRAME, MAP_FRAME, RobotPose
from sid.perception.skeleton import skeleton_world
from sid.synthetic.body import body_capsules
from sid.synthetic.noise import DepthNoise, KeypointNoise
from sid.synthetic.render import LABEL_GROUND, LABEL_NONE, LABEL_WALL, Background, Capsule, RayCaster, Rendering
from sid.synthetic.scene import Scene, ScenePerson
from sid.synthetic.sequence import SyntheticSequence
from sid.synthetic.truth import TruthGroup, truth_groups

__all__ = [
    "D435I_COLOR",
    "D435I_DEPTH",
    "D435I_DEPTH_TO_COLOR",
    "FrameTruth",
    "PERSON_COLORS",
    "SyntheticCamera",
    "TruthPerson",
    "d435i_calibration",
]

D435I_COLOR = Intrinsics(1280, 720, 910.0, 910.0, 639.5, 359.5)
D435I_DEPTH = Intrinsics(848, 480, 420.0, 420.0, 423.5, 239.5)
D435I_DEPTH_TO_COLOR = Extrinsics(np.eye(3), np.array([0.015, 0.0, 0.0]))


def d435i_calibration(registered: bool = False) -> Calibration:
    """Typical D435i calibration; ``registered``: depth already in the colour grid (``depth`` None)."""
    if registered:
        return Calibration(D435I_COLOR, None, Extrinsics(), 0.001)
    return Calibration(D435I_COLOR, D435I_DEPTH, D435I_DEPTH_TO_COLOR, 0.001)


@dataclass
class TruthPerson:
    """Ground truth of one person in one frame.

    x, y (m), theta (rad), height (m), keypoints_world (17, 3) joints (m), vx, vy (m/s): in the truth's frame
    (``FrameTruth.frame_id``). walking: moving along a path (else standing, velocity 0). in_view: at least one
    keypoint visible (in the colour image and not hidden behind someone else).
    keypoints_px (17, 2): their exact colour-image pixels (u, v); NaN behind the camera. visible (17,): inside the
    colour image and not hidden behind another person. self_occluded (17,): behind the person's own body surface
    by more than the camera's ``self_occlusion_margin`` (a pose model still guesses these, less confidently; see
    ``TruthPose``). observed_px (17, 2) / observed (17,): what a pose model reports: pixels with noise, and the
    visible keypoints that were not dropped. box (4,): the
    whole body's box in colour pixels (u_min, v_min, u_max, v_max) ignoring occlusion, clipped to the image.
    """

    id: int
    x: float
    y: float
    theta: float
    height: float
    keypoints_world: np.ndarray = field(repr=False)
    keypoints_px: np.ndarray = field(repr=False)
    visible: np.ndarray = field(repr=False)
    self_occluded: np.ndarray = field(repr=False)
    observed_px: np.ndarray = field(repr=False)
    observed: np.ndarray = field(repr=False)
    box: np.ndarray = field(repr=False)
    vx: float = 0.0
    vy: float = 0.0
    walking: bool = False
    in_view: bool = True


@dataclass
class FrameTruth:
    """What a synthetic frame shows: the scene's name, people and groups (the conversations that hold at the
    frame's time), the camera mount used, and the frame of positions: ``"map"`` for a ``SyntheticSequence``,
    ``"base_footprint"`` for a static ``Scene``."""

    scene: str
    people: list[TruthPerson]
    groups: list[TruthGroup]
    mount: CameraMount
    frame_id: str = BASE_FRAME


@dataclass
class _SceneRender:
    """The exact images and keypoints of people as the camera sees them (keypoints in base_footprint)."""

    depth: Rendering
    color: np.ndarray
    keypoints_world: list[np.ndarray]
    keypoints_px: list[np.ndarray]
    visible: list[np.ndarray]
    self_occluded: list[np.ndarray]
    boxes: list[np.ndarray]


@dataclass(eq=False)
class _StillLayer:
    """Depth and shaded colour renders of the people who stand still in the camera's view (``key``: which people,
    as (index, pose), and which views), and the colour render painted for one robot pose (``painted``)."""

    key: tuple
    depth: Rendering
    color: Rendering | None
    painted: tuple[RobotPose | None, np.ndarray] | None = None


@dataclass(eq=False)
class _Floor:
    """The empty scene's colour image with a plain light floor, and the floor's pixels: flat indices into the image
    and their robot-frame ground coordinates x, y (m)."""

    image: np.ndarray
    pixels: np.ndarray
    x: np.ndarray
    y: np.ndarray

    @classmethod
    def of(cls, rendering: Rendering, background_world: np.ndarray) -> _Floor:
        """From a colour caster's empty rendering and the world point of each background pixel."""
        label = rendering.label
        image = np.empty(label.shape + (3,), dtype=np.uint8)
        image[label == LABEL_NONE] = _SKY
        image[label == LABEL_WALL] = _WALL
        ground = label == LABEL_GROUND
        image[ground] = _GROUND_LIGHT
        floor = background_world[ground]
        return cls(image, np.flatnonzero(ground), floor[:, 0].copy(), floor[:, 1].copy())

    def painted(self, pose: RobotPose | None) -> np.ndarray:
        """(H, W, 3) uint8 RGB of the empty scene: the floor checkered in ``_CHECKER_M`` squares fixed to the map
        (the robot at ``pose``), or to the robot when ``pose`` is None; a plain wall; the sky."""
        x, y = self.x, self.y
        if pose is not None:
            c, s = np.float32(np.cos(pose.yaw)), np.float32(np.sin(pose.yaw))
            x, y = c * self.x - s * self.y + np.float32(pose.x), s * self.x + c * self.y + np.float32(pose.y)
        dark = (np.floor(x / _CHECKER_M) + np.floor(y / _CHECKER_M)) % 2 == 1
        image = self.image.copy()
        image.reshape(-1, 3)[self.pixels[dark]] = _GROUND_DARK
        return image


@dataclass(eq=False)
class _Views:
    """The cameras' ray casters for one mount and background, and the colour camera's empty floor."""

    depth: RayCaster
    color: RayCaster | None
    floor: _Floor | None

    @property
    def registered(self) -> bool:
        """Whether depth is cast on the colour camera's rays (registered depth): then the shaded colour render
        carries the depth and labels too, and the scene is cast once, not twice."""
        return self.depth is self.color


# Flat colours (RGB) of the first people; more people cycle through them.
PERSON_COLORS = np.array(
    [[220, 60, 50], [50, 110, 220], [40, 170, 80], [230, 160, 30], [150, 70, 200], [30, 180, 190]], dtype=float
)
_SKY = np.array([200, 215, 230], dtype=float)
_WALL = np.array([215, 205, 185], dtype=float)
_GROUND_LIGHT, _GROUND_DARK = np.array([150, 150, 150], dtype=float), np.array([115, 115, 115], dtype=float)
_CHECKER_M = 0.5  # side of the ground's checkerboard squares
_MAX_CACHED_VIEWS = 8  # ray casters (mount, background) kept between scenes


class SyntheticCamera:
    """Renders scenes as a D435i-like RGB-D camera would see them.

    calibration: default ``d435i_calibration(registered)``; with ``calibration.depth`` None the depth is rendered in
    the colour grid. registered: only without a calibration (one that says otherwise is refused). noise /
    keypoint_noise: see ``sid.synthetic.noise`` (``DepthNoise.exact()`` and ``KeypointNoise(0, 0)`` for perfect
    data). sensor_focal_px: focal length (px, > 0) of the stereo pair for the noise model when depth is registered
    (default the D435's 420 px at 848x480); with depth intrinsics the noise uses their fx, and another value is
    refused. occlusion_margin (m): a keypoint is
    hidden when another person's surface lies this much nearer at its pixel. self_occlusion_margin (m): a keypoint
    is self-occluded when its own body's surface lies this much nearer (joints sit a few centimetres inside limbs and
    torso seen from the front, the face seen from behind and the far limbs of someone in profile much deeper; the
    default lies between them: docs/reproduction.md, "The self-occlusion margin"); None: never. shaded_color: render
    the colour image (flat-shaded people on a checkered floor); False gives a plain grey image (faster, for metrics
    only).
    group_params: detector parameters used for the groups' exact interest point and area (see ``truth``).
    """

    def __init__(
        self,
        calibration: Calibration | None = None,
        registered: bool | None = None,
        noise: DepthNoise | None = None,
        keypoint_noise: KeypointNoise | None = None,
        sensor_focal_px: float | None = None,
        occlusion_margin: float = 0.10,
        self_occlusion_margin: float | None = 0.15,
        shaded_color: bool = True,
        fps: float = 30.0,
        group_params: GroupParams | None = None,
    ):
        if calibration is not None and registered is not None and registered != (calibration.depth is None):
            said = "registered" if calibration.depth is None else "not registered (it has depth intrinsics)"
            raise InputError(
                f"synthetic camera: registered={registered} contradicts the calibration, whose depth is {said}; "
                "pass registered only without a calibration"
            )
        self.calibration = calibration or d435i_calibration(bool(registered))
        self.noise = noise if noise is not None else DepthNoise()
        self.keypoint_noise = keypoint_noise if keypoint_noise is not None else KeypointNoise()
        depth = self.calibration.depth
        if depth is not None and sensor_focal_px is not None and sensor_focal_px != depth.fx:
            raise InputError(
                f"synthetic camera: sensor_focal_px {sensor_focal_px} contradicts the calibration's depth fx "
                f"{depth.fx}; sensor_focal_px is for registered depth only (unregistered depth uses its own fx)"
            )
        if depth is not None:
            sensor_focal_px = depth.fx
        elif sensor_focal_px is None:
            sensor_focal_px = D435I_DEPTH.fx
        check_number("synthetic camera", "sensor_focal_px", sensor_focal_px, low=0, low_open=True, unit="pixels")
        self.sensor_focal_px = float(sensor_focal_px)
        self.occlusion_margin = float(occlusion_margin)
        self.self_occlusion_margin = None if self_occlusion_margin is None else float(self_occlusion_margin)
        margins = ["occlusion_margin"] + ([] if self.self_occlusion_margin is None else ["self_occlusion_margin"])
        check_numbers("synthetic camera", self, margins, low=0, unit="metres")
        self.shaded_color = shaded_color
        check_number("synthetic camera", "fps", fps, low=0, low_open=True)
        self.fps = float(fps)
        self.group_params = group_params or GroupParams()
        self._cached: tuple[tuple, _SceneRender] | None = None
        self._still: _StillLayer | None = None
        self._bodies: dict[ScenePerson, tuple[np.ndarray, list[Capsule]]] = {}
        self._cached_groups: tuple[tuple, list[TruthGroup]] | None = None
        self._views: dict[tuple[CameraMount, float | None], _Views] = {}

    def forget_renders(self) -> None:
        """Drop the kept exact renders, bodies and group geometry: the next ``capture`` casts its scene afresh. The
        ray casters of each mount and background stay (they are built once per stream)."""
        self._cached = None
        self._still = None
        self._bodies = {}
        self._cached_groups = None

    @property
    def depth_intrinsics(self) -> Intrinsics:
        return self.calibration.depth or self.calibration.color

    def world_to_color(self, mount: CameraMount) -> Extrinsics:
        """World -> colour-camera optical frame for this mount."""
        rotation = mount.rotation.T
        return Extrinsics(rotation, -rotation @ mount.position)

    def world_to_depth(self, mount: CameraMount) -> Extrinsics:
        """World -> depth-camera optical frame (the colour frame when depth is registered)."""
        to_color = self.world_to_color(mount)
        if self.calibration.depth is None:
            return to_color
        d2c = self.calibration.depth_to_color
        rotation = d2c.rotation.T @ to_color.rotation
        return Extrinsics(rotation, d2c.rotation.T @ (to_color.translation - d2c.translation))

    def capture(self, scene: Scene | SyntheticSequence, index: int = 0, seed: int = 0) -> Frame:
        """Frame ``index`` of ``scene`` (a ``SyntheticSequence`` at time ``index / fps``): noisy depth (depth grid,
        float32 m), colour image, truth, and for a ``SyntheticSequence`` the robot's pose."""
        time = index / self.fps
        pose: RobotPose | None = None
        velocities: dict[int, tuple[float, float]] = {}
        if isinstance(scene, SyntheticSequence):
            moment = scene.at(time)
            pose, people, seen, groups = moment.robot_pose, moment.people, moment.seen_people, moment.groups
            velocities = {i: (m.vx, m.vy) for i, m in moment.states.items()}
            driving = scene.robot.at(time).moving
            moving = tuple(driving or moment.states[p.id].moving for p in people)
        else:
            people, seen, groups = scene.people, scene.people, scene.groups
            moving = (False,) * len(people)
        render = self._render_scene(scene, seen, moving, pose)
        rng = np.random.default_rng([seed, index])
        depth = self.noise.apply(render.depth.depth, self.sensor_focal_px, rng, image_focal_px=self.depth_intrinsics.fx)
        truth_people = []
        for i, person in enumerate(people):
            observed_px, kept = self.keypoint_noise.apply(render.keypoints_px[i], rng)
            keypoints = render.keypoints_world[i]
            if pose is not None:
                keypoints = np.column_stack([pose.to_map(keypoints[:, :2]), keypoints[:, 2]])
            vx, vy = velocities.get(person.id, (0.0, 0.0))
            # each frame's truth owns its arrays: the render they come from is kept for the next frames
            truth_people.append(
                TruthPerson(
                    person.id,
                    person.x,
                    person.y,
                    person.theta,
                    person.height,
                    keypoints.copy() if pose is None else keypoints,
                    render.keypoints_px[i].copy(),
                    render.visible[i].copy(),
                    render.self_occluded[i].copy(),
                    observed_px,
                    render.visible[i] & kept,
                    render.boxes[i].copy(),
                    vx,
                    vy,
                    vx != 0.0 or vy != 0.0,
                    bool(render.visible[i].any()),
                )
            )
        truth = FrameTruth(
            scene.name,
            truth_people,
            self._truth_groups(people, groups),
            scene.mount,
            BASE_FRAME if pose is None else MAP_FRAME,
        )
        return Frame(index, render.color.copy(), depth, self.calibration, time, truth, pose)

    def exact_depth(self, scene: Scene) -> Rendering:
        """The noise-free depth and label images of ``scene`` in the depth grid (labels: person index in
        ``scene.people``, or ``render.LABEL_*``)."""
        return self._render_scene(scene, scene.people, (False,) * len(scene.people), None).depth

    def _truth_groups(self, people: tuple[ScenePerson, ...], groups: tuple[tuple[int, ...], ...]) -> list[TruthGroup]:
        """The groups' exact geometry, kept while their members stay where they are."""
        members = {m for g in groups for m in g}
        people = tuple(p for p in people if p.id in members)
        key = (people, groups)
        if self._cached_groups is None or self._cached_groups[0] != key:
            self._cached_groups = (key, truth_groups(people, groups, self.group_params))
        return self._cached_groups[1]

    def _render_scene(
        self,
        scene: Scene | SyntheticSequence,
        people: tuple[ScenePerson, ...],
        moving: tuple[bool, ...],
        pose: RobotPose | None,
    ) -> _SceneRender:
        """The exact render of ``people`` (base_footprint) with the scene's mount and background. ``moving``: which
        of them move in the camera's view; the others are cast once and kept while they stay (``_StillLayer``).
        pose: the robot's pose in the map, which the floor's pattern is fixed to (None: fixed to the robot)."""
        wall = scene.wall_distance if isinstance(scene, Scene) else None
        key = (people, scene.mount, wall, pose)
        if self._cached is not None and self._cached[0] == key:
            return self._cached[1]
        self._bodies = {p: self._bodies.get(p) or _body(p) for p in people}
        keypoints_world = [self._bodies[p][0] for p in people]
        bodies = [self._bodies[p][1] for p in people]
        views = self._cameras(scene.mount, wall)
        movers = [i for i, m in enumerate(moving) if m]
        still = self._still_layer(views, pose, tuple((i, p) for i, p in enumerate(people) if not moving[i]), bodies)
        color_intr = self.calibration.color
        shaded = None
        if views.color is not None:
            assert still.color is not None and still.painted is not None  # made with the colour caster
            shaded = views.color.render([bodies[i] for i in movers], shading=True, labels=movers, base=still.color)
            color = _paint(shaded, still.painted[1], still.color)
        else:
            color = np.full((color_intr.height, color_intr.width, 3), 128, dtype=np.uint8)
        if views.registered and shaded is not None:
            depth = shaded
        else:
            depth = views.depth.render([bodies[i] for i in movers], labels=movers, base=still.depth)
        to_depth, to_color = views.depth.world_to_camera, self.world_to_color(scene.mount)
        keypoints_px, visible, self_occluded, boxes = [], [], [], []
        for i, kp in enumerate(keypoints_world):
            px = project(to_color.apply(kp), color_intr)
            keypoints_px.append(px)
            by_others, by_self = self._occlusion(kp, i, depth, to_depth)
            visible.append(_inside(px, color_intr) & ~by_others)
            self_occluded.append(by_self)
            boxes.append(_body_box(kp, people[i].height, to_color, color_intr))
        render = _SceneRender(depth, color, keypoints_world, keypoints_px, visible, self_occluded, boxes)
        self._cached = (key, render)
        return render

    def _still_layer(
        self,
        views: _Views,
        pose: RobotPose | None,
        still: tuple[tuple[int, ScenePerson], ...],
        bodies: list[list[Capsule]],
    ) -> _StillLayer:
        """The renders of the people who do not move (index, person), kept while they and the views stay, and
        painted over the floor as seen from ``pose`` (repainted when the robot moves)."""
        key = (still, views)
        if self._still is None or self._still.key != key:
            labels = [i for i, _ in still]
            chosen = [bodies[i] for i in labels]
            color = None if views.color is None else views.color.render(chosen, shading=True, labels=labels)
            depth = color if views.registered and color is not None else views.depth.render(chosen, labels=labels)
            self._still = _StillLayer(key, depth, color)
        layer = self._still
        if layer.color is not None and (layer.painted is None or layer.painted[0] != pose):
            assert views.floor is not None  # made with the colour caster
            layer.painted = (pose, _paint(layer.color, views.floor.painted(pose)))
        return layer

    def _cameras(self, mount: CameraMount, wall_distance: float | None) -> _Views:
        """Ray casters (and the painted background) for a mount and wall, kept for the next scenes (variations of
        a layout share them)."""
        key = (mount, wall_distance)
        if key not in self._views:
            if len(self._views) >= _MAX_CACHED_VIEWS:
                self._views.clear()
            background = Background(ground=True, wall_distance=wall_distance)
            color, floor = None, None
            if self.shaded_color:
                color = RayCaster(self.calibration.color, self.world_to_color(mount), background)
                floor = _Floor.of(color.render([], shading=True), color.background_world)
            registered = color is not None and self.calibration.depth is None
            depth = color if registered else RayCaster(self.depth_intrinsics, self.world_to_depth(mount), background)
            assert depth is not None
            self._views[key] = _Views(depth, color, floor)
        return self._views[key]

    def _occlusion(
        self, keypoints: np.ndarray, index: int, depth: Rendering, to_depth: Extrinsics
    ) -> tuple[np.ndarray, np.ndarray]:
        """(17,) bool pair: keypoints behind another person's surface by more than ``occlusion_margin``, and behind
        their own body's surface by more than ``self_occlusion_margin``, as the depth camera sees them."""
        points = to_depth.apply(keypoints)
        px = project(points, self.depth_intrinsics)
        by_others = np.zeros(NUM_KEYPOINTS, dtype=bool)
        by_self = np.zeros(NUM_KEYPOINTS, dtype=bool)
        inside = _inside(px, self.depth_intrinsics)
        u, v = (np.rint(px[inside]).astype(int)).T
        label = depth.label[v, u]
        in_front = points[inside, 2] - depth.depth[v, u]  # how far the surface at the pixel lies before the joint
        by_others[inside] = (label >= 0) & (label != index) & (in_front > self.occlusion_margin)
        if self.self_occlusion_margin is not None:
            by_self[inside] = (label == index) & (in_front > self.self_occlusion_margin)
        return by_others, by_self


def _body(person: ScenePerson) -> tuple[np.ndarray, list[Capsule]]:
    """(17, 3) joints and the capsules of one person's body (same frame as the person)."""
    keypoints = skeleton_world(person.x, person.y, person.theta, person.height)
    return keypoints, body_capsules(keypoints, person.height)


def _inside(px: np.ndarray, intr: Intrinsics) -> np.ndarray:
    with np.errstate(invalid="ignore"):
        return (
            np.isfinite(px).all(axis=1)
            & (px[:, 0] >= -0.5)
            & (px[:, 0] < intr.width - 0.5)
            & (px[:, 1] >= -0.5)
            & (px[:, 1] < intr.height - 0.5)
        )


def _body_box(keypoints: np.ndarray, height: float, to_color: Extrinsics, intr: Intrinsics) -> np.ndarray:
    """Box (u_min, v_min, u_max, v_max) of the body in colour pixels: keypoints, the top of the head and the
    floor under the feet, widened sideways (u only) by 0.12 m (body radius) at each point's depth; v spans the
    points as they are; clipped to the image."""
    centre = keypoints[[15, 16]].mean(axis=0)
    extra = np.array([[centre[0], centre[1], height], [centre[0], centre[1], 0.0]])
    points = to_color.apply(np.vstack([keypoints, extra]))
    points = points[points[:, 2] > 1e-3]
    if len(points) == 0:
        return np.array([np.nan] * 4)
    px = project(points, intr)
    pad = 0.12 * intr.fx / points[:, 2]
    box = np.array([(px[:, 0] - pad).min(), px[:, 1].min(), (px[:, 0] + pad).max(), px[:, 1].max()])
    box[[0, 2]] = np.clip(box[[0, 2]], -0.5, intr.width - 0.5)
    box[[1, 3]] = np.clip(box[[1, 3]], -0.5, intr.height - 0.5)
    return box


def _paint(rendering: Rendering, backdrop: np.ndarray, under: Rendering | None = None) -> np.ndarray:
    """RGB uint8 image: people in flat colours shaded by the viewing angle, in front of the backdrop.

    under: the base rendering ``rendering`` was drawn over (``RayCaster.render(base=...)``); ``backdrop`` is then
    ``under`` painted, and only the pixels the new bodies took (their labels differ) are painted over it."""
    label, shade = rendering.label, rendering.shade
    assert shade is not None, "_paint needs a rendering made with shading=True"
    image = backdrop.copy()
    people = label >= 0 if under is None else label != under.label
    colors = PERSON_COLORS[label[people] % len(PERSON_COLORS)]
    image[people] = np.clip(colors * (0.35 + 0.65 * shade[people])[:, None], 0, 255).astype(np.uint8)
    return image

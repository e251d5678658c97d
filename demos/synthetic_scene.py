"""A synthetic RGB-D scene: the paper's layout S3 seen by a virtual RealSense D435i, with its ground truth.

Renders a few frames of three people on an equilateral triangle facing its centre, prints each person's truth
and what the noisy depth camera measures on them, and saves the colour image and a colourised depth image.
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

from sid.perception.camera import project
from sid.perception.keypoints import KP
from sid.sources.synthetic import SyntheticSource
from sid.synthetic.layouts import LAYOUTS
from sid.synthetic.pose import TruthPose
from sid.synthetic.scene import Scene

TORSO = [KP["left_shoulder"], KP["right_shoulder"], KP["left_hip"], KP["right_hip"]]

source = SyntheticSource("S3", frames=8, seed=0)
frames = list(source)
camera = source.camera
calib = frames[0].calibration
depth_camera = camera.depth_intrinsics  # the frames' depth camera (calib.depth)
scene = source.scene
assert isinstance(scene, Scene), "S3 is one scene, not a moving sequence"
print(f"S3: {LAYOUTS['S3'].description}; {len(frames)} frames")
print(f"colour {calib.color.width}x{calib.color.height} fx={calib.color.fx:.0f} px, depth {depth_camera.width}x"
      f"{depth_camera.height} fx={depth_camera.fx:.0f} px, camera {scene.mount.height} m high")  # fmt: skip

# Per person: the truth, and the depth readings at the torso centre across frames.
to_depth = camera.world_to_depth(scene.mount)
print("\n id     x      y   theta  visible  self-occl.  torso z (exact)  mean reading  RMS error (model)")
for person in frames[0].truth.people:
    torso = to_depth.apply(person.keypoints_world[TORSO].mean(axis=0)[None])
    u, v = np.rint(project(torso, camera.depth_intrinsics)[0]).astype(int)
    exact = float(camera.exact_depth(scene).depth[v, u])  # the body's surface in front of the spine
    readings = np.array([frame.depth[v, u] for frame in frames], dtype=float)
    readings = readings[readings > 0]
    rms_mm = np.sqrt(np.mean((readings - exact) ** 2)) * 1000
    model_mm = camera.noise.rms(exact, depth_camera.fx) * 1000
    print(f"{person.id:3d} {person.x:5.2f} {person.y:6.2f} {np.degrees(person.theta):6.0f}   "
          f"{person.visible.sum():3d}/17     {person.self_occluded.sum():3d}         {exact:.3f} m        "
          f"{readings.mean():.3f} m    {rms_mm:4.1f} mm ({model_mm:.1f})")  # fmt: skip

(group,) = frames[0].truth.groups
print(f"\ngroup {group.members}: interest point ({group.interest_point[0]:.2f}, {group.interest_point[1]:.2f}) m, "
      f"area {group.area:.3f} m^2")  # fmt: skip

depth = frames[0].depth
valid = depth > 0
print(f"depth frame 0: {valid.mean():.1%} valid pixels, range {depth[valid].min():.2f}-{depth[valid].max():.2f} m")
detections = TruthPose()(frames[0])
print(f"TruthPose: {len(detections)} people, mean keypoint score {np.mean([d.scores.mean() for d in detections]):.2f}")

out = Path("synthetic_scene")
out.mkdir(exist_ok=True)
cv2.imwrite(str(out / "color.png"), cv2.cvtColor(frames[0].color, cv2.COLOR_RGB2BGR))
colourised = cv2.applyColorMap(np.clip(depth / 6.0 * 255, 0, 255).astype(np.uint8), cv2.COLORMAP_TURBO)
colourised[~valid] = 0  # holes in black
cv2.imwrite(str(out / "depth.png"), colourised)
print(f"pictures: {out / 'color.png'}, {out / 'depth.png'} (depth 0-6 m, holes black)")

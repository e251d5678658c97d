"""Synthetic RGB-D scenes: people rendered as simple solids, seen by a virtual RealSense D435i, with ground truth.

>>> from sid.sources.synthetic import SyntheticSource
>>> for frame in SyntheticSource("S3", frames=100, seed=0):   # the paper's layout S3
...     frame.depth            # (480, 848) float32 metres, D435-like noise, depth camera grid
...     frame.truth.people[0]  # exact position, facing, 3D and 2D keypoints, visibility
>>> from sid.synthetic.pose import TruthPose                   # pose "model" reading the truth
>>> detections = TruthPose()(frame)
>>> for frame in SyntheticSource("crossing_walkers"):          # a moving scene, 30 fps until everyone stops
...     frame.robot_pose, frame.truth.people[5].walking        # map-frame truth, velocities, visibility

Modules, in the order data flows:

- ``scene``: ``Scene`` / ``ScenePerson`` records of a static scene (robot frame) and scene files (JSON/YAML).
- ``sequence``: ``SyntheticSequence``, a scene in motion read from a costmap scenario file (people walking along paths,
  the robot driving, declared conversations; map frame), and the built-in sequences (``builtin_sequence``).
- ``layouts``: the paper's S1-S5 as parameterised formations, and their documented variations.
- ``body``: 15 capsules (torso, head, limbs) around each person's COCO skeleton (``sid.perception.skeleton``).
- ``render``: exact depth / label / shading images by analytic ray-capsule intersection (ground, back wall).
- ``noise``: D435 depth noise (Intel's RMS model, quantisation, holes, stereo shadow), keypoint noise.
- ``sensor``: ``SyntheticCamera``, the virtual D435i (colour 1280x720, depth 848x480, 15 mm apart) that turns a
  scene or a sequence into a ``sid.perception.frame.Frame`` with ``FrameTruth`` (and the robot's pose).
- ``truth``: ground-truth groups (interest point and area as the group detector defines them on exact data).
- ``pose``: ``TruthPose``, the pose stand-in.
"""

from sid.synthetic.layouts import LAYOUTS, Formation, layout, variations
from sid.synthetic.noise import DepthNoise, KeypointNoise
from sid.synthetic.scene import Scene, ScenePerson
from sid.synthetic.sensor import FrameTruth, SyntheticCamera, TruthPerson, d435i_calibration
from sid.synthetic.sequence import SEQUENCES, SyntheticSequence, builtin_sequence
from sid.synthetic.truth import TruthGroup

__all__ = [
    "LAYOUTS",
    "SEQUENCES",
    "DepthNoise",
    "Formation",
    "FrameTruth",
    "KeypointNoise",
    "Scene",
    "ScenePerson",
    "SyntheticSequence",
    "SyntheticCamera",
    "TruthGroup",
    "TruthPerson",
    "builtin_sequence",
    "d435i_calibration",
    "layout",
    "variations",
]

"""Pose estimation on one image: load an ONNX pose model, find people, print them and save an overlay picture.

With the project's shared test material next to the repository (../shared), this runs the real YOLO11n-pose
model on a real frame with five people. Without it, it builds a tiny stand-in model with MoveNet MultiPose's
signature (it reports a "person" wherever the image is reddest) so the same calls still run end to end.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import cv2
import numpy as np

from sid.perception.keypoints import KP
from sid.perception.overlay import draw_detections
from sid.perception.pose import load_pose_estimator

SHARED = Path(__file__).resolve().parents[1].parent / "shared"


def real_inputs(shared: Path) -> tuple[Path, np.ndarray] | None:
    """The real YOLO-pose model and five-people frame (RGB), or None when ../shared is absent."""
    model = shared / "models" / "yolo11n-pose-256.onnx"
    image = shared / "data" / "rgbd" / "five_people" / "color.png"
    if not (model.is_file() and image.is_file()):
        return None
    return model, cv2.cvtColor(cv2.imread(str(image)), cv2.COLOR_BGR2RGB)


def stand_in_inputs(folder: Path) -> tuple[Path, np.ndarray]:
    """A tiny MultiPose-signature model (needs the `onnx` package) and a grey image with a red blob at (400, 100)."""
    from sid.testing import build_multipose_model

    # A stick figure facing the camera (its left on the image's right): (dy, dx) of each keypoint from the blob
    # on the nose, normalised to the model input.
    figure = {"nose": (0, 0), "eye": (-0.02, 0.012), "ear": (-0.01, 0.025), "shoulder": (0.1, 0.06)}
    figure |= {"elbow": (0.25, 0.08), "wrist": (0.38, 0.08), "hip": (0.4, 0.04), "knee": (0.57, 0.045)}
    figure |= {"ankle": (0.74, 0.045)}
    offsets = np.array([figure[name.split("_")[-1]] for name in KP], dtype=float)
    offsets[[i for name, i in KP.items() if name.startswith("right")], 1] *= -1
    person = np.zeros((6, 56))
    person[0, :51] = np.column_stack([offsets, np.full(17, 0.8)]).ravel()
    person[0, 51:] = [-0.06, -0.11, 0.78, 0.11, 0.9]  # box (ymin, xmin, ymax, xmax) around the figure, score 0.9
    model = build_multipose_model(folder / "stand_in_multipose.onnx", person, marker=True)
    image = np.full((480, 640, 3), 120, np.uint8)
    cv2.circle(image, (400, 100), 6, (255, 0, 0), cv2.FILLED)  # RGB red
    return model, image


def main(shared: Path = SHARED) -> None:
    out_dir = Path(tempfile.mkdtemp(prefix="sid_pose_demo_"))
    inputs = real_inputs(shared)
    if inputs is None:
        print(f"{shared} absent: using a tiny stand-in model with the MoveNet MultiPose signature")
        inputs = stand_in_inputs(out_dir)
    model_path, color = inputs

    estimator = load_pose_estimator(model_path)  # contract read from the model's own signature
    people = estimator(color)
    print(f"{model_path.name}: contract {estimator.contract}, {estimator.model.threads} threads, {len(people)} people")
    for i, person in enumerate(people):
        shoulders = person.keypoints[[KP["left_shoulder"], KP["right_shoulder"]]]
        print(
            f"  person {i}: score {person.box_score:.2f}, box (u, v) {np.round(person.box).astype(int).tolist()}, "
            f"shoulders {np.round(shoulders).astype(int).tolist()} px"
        )
    picture = out_dir / "pose_overlay.png"
    cv2.imwrite(str(picture), draw_detections(color, people))
    print(f"overlay written to {picture}")


if __name__ == "__main__":
    main()

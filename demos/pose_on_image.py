"""Pose estimation on one image: load an ONNX pose model, find people, print them and save an overlay picture.

Run: python demos/pose_on_image.py [MODEL.onnx [IMAGE]]. Without arguments it uses the project's shared material
next to the repository (../shared: the YOLO11n-pose model and a real frame with five people); without that either,
it says where to get a model (docs/models.md) and stops.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import cv2
import numpy as np

from sid.perception.keypoints import KP
from sid.perception.overlay import draw_detections
from sid.perception.pose import load_pose_estimator

SHARED = Path(__file__).resolve().parents[1].parent / "shared"
MODEL = SHARED / "models" / "yolo11n-pose-256.onnx"
IMAGE = SHARED / "data" / "rgbd" / "five_people" / "color.png"


def main(model_path: Path = MODEL, image_path: Path = IMAGE) -> int:
    """Run the model on the image (RGB); 0 when it ran, 1 when the model or image is missing."""
    missing = [str(p) for p in (model_path, image_path) if not p.is_file()]
    if missing:
        print(
            f"not found: {', '.join(missing)}. Pass a pose model and an image: python demos/pose_on_image.py "
            "MODEL.onnx IMAGE.png (where to get a model: docs/models.md)"
        )
        return 1
    image = cv2.imread(str(image_path))
    if image is None:
        print(f"cannot read {image_path} as an image (PNG, JPEG, ...)")
        return 1
    color = cv2.cvtColor(image, cv2.COLOR_BGR2RGB)

    estimator = load_pose_estimator(model_path)  # contract read from the model's own signature
    people = estimator(color)
    print(f"{model_path.name}: contract {estimator.contract}, {estimator.model.threads} threads, {len(people)} people")
    for i, person in enumerate(people):
        shoulders = person.keypoints[[KP["left_shoulder"], KP["right_shoulder"]]]
        print(
            f"  person {i}: score {person.box_score:.2f}, box (u, v) {np.round(person.box).astype(int).tolist()}, "
            f"shoulders {np.round(shoulders).astype(int).tolist()} px"
        )
    picture = Path(tempfile.mkdtemp(prefix="sid_pose_demo_")) / "pose_overlay.png"
    cv2.imwrite(str(picture), draw_detections(color, people))
    print(f"overlay written to {picture}")
    return 0


if __name__ == "__main__":
    arguments = [Path(arg) for arg in sys.argv[1:3]]
    status = main(*arguments)
    sys.exit(status if arguments else 0)  # without arguments a missing ../shared is a documented stop, not a failure

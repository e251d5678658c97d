"""A pose "model" that reads a synthetic frame's ground truth, so the whole pipeline runs without a network.

It reports what ``SyntheticCamera`` says a pose model would see: every person with enough observed keypoints, at
their noisy pixels (``TruthPerson.observed_px``). Scores mimic how a real model's confidence behaves:

- visible keypoints: ``score_observed``;
- keypoints hidden behind the person's own body (the far shoulder, hip or arm of someone in profile): real models
  still place them from the body's shape, with less confidence: ``score_self_occluded``;
- the face (nose, eyes) of someone seen from behind, keypoints hidden behind another person or dropped:
  ``score_hidden`` (their positions are still reported, as real models do).

Unlike a real ``PoseEstimator`` it is called with the whole ``Frame`` (it needs ``frame.truth``), not with the
colour image.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sid.errors import InputError
from sid.perception.frame import Frame
from sid.perception.keypoints import KP, NUM_KEYPOINTS, PoseDetection
from sid.synthetic.sensor import FrameTruth

__all__ = ["TruthPose"]

_FACE = np.isin(np.arange(NUM_KEYPOINTS), [KP["nose"], KP["left_eye"], KP["right_eye"]])


@dataclass(frozen=True)
class TruthPose:
    """Pose stand-in for synthetic frames.

    score_observed / score_self_occluded / score_hidden: keypoint scores (see the module docstring; choose them
    around the pipeline's keypoint threshold to decide what it uses). min_observed: people with fewer observed
    keypoints are not reported (a real detector misses them too).
    """

    score_observed: float = 0.9
    score_self_occluded: float = 0.5
    score_hidden: float = 0.05
    min_observed: int = 3

    contract = "truth"
    input_size = None

    def __post_init__(self) -> None:
        if not 0.0 <= self.score_hidden <= self.score_self_occluded <= self.score_observed <= 1.0:
            raise InputError(
                "truth pose: need 0 <= score_hidden <= score_self_occluded <= score_observed <= 1, got "
                f"{self.score_hidden}, {self.score_self_occluded}, {self.score_observed}"
            )
        if self.min_observed < 1:
            raise InputError(f"truth pose: min_observed must be >= 1, got {self.min_observed}")

    def __call__(self, frame: Frame) -> list[PoseDetection]:
        """People of ``frame.truth`` as pose detections (colour-image pixels), in the truth's order."""
        truth = getattr(frame, "truth", None)
        if not isinstance(truth, FrameTruth):
            raise InputError(
                "truth pose: the frame carries no synthetic ground truth (frame.truth); TruthPose only works on "
                "frames from sid.sources.synthetic - use a real pose model for other sources"
            )
        detections = []
        for person in truth.people:
            count = int(np.count_nonzero(person.observed))
            if count < self.min_observed:
                continue
            scores = np.full(NUM_KEYPOINTS, self.score_hidden)
            scores[person.observed & ~person.self_occluded] = self.score_observed
            scores[person.observed & person.self_occluded & ~_FACE] = self.score_self_occluded
            box_score = self.score_observed * count / NUM_KEYPOINTS
            detections.append(PoseDetection(person.observed_px.copy(), scores, person.box.copy(), box_score))
        return detections

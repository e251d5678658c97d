"""PeopleStream: the per-frame pipeline, then the people and group trackers, on whole frames or posed ones."""

from __future__ import annotations

from dataclasses import replace

import pytest

from sid.perception.pipeline import FrameResult, Pipeline, PosedFrame
from sid.sources.synthetic import SyntheticSource
from sid.synthetic.pose import TruthPose
from sid.tracking import PeopleStream, TrackingError


def _tracks_json(steps: list) -> list[list[dict]]:
    return [[p.to_json() for p in step.tracks.people] + [g.to_json() for g in step.tracks.groups] for step in steps]


def test_posed_frames_give_the_tracks_whole_frames_give() -> None:
    """``update_posed`` (the pose stage run elsewhere, as ``sid detect`` runs it ahead) and ``update`` agree."""
    source = SyntheticSource("S1", frames=24, seed=2)
    frames = list(source)
    whole, halves = (PeopleStream(Pipeline(TruthPose(), source.scene.mount)) for _ in range(2))
    by_frame = [whole.update(frame) for frame in frames]
    by_half = [halves.update_posed(halves.pipeline.pose_frame(frame)) for frame in frames]
    assert _tracks_json(by_frame) == _tracks_json(by_half)
    assert by_frame[-1].tracks.people and by_frame[-1].tracks.groups  # a conversation tracked, not two empty lists
    assert [s.result.frame for s in by_half] == [f.index for f in frames]
    assert {"track", "track_groups"} <= by_half[-1].tracks.timing_ms.keys()


class CountingPipeline(Pipeline):
    """The real pipeline, counting the frames whose stages after the pose ran."""

    located = 0

    def locate(self, posed: PosedFrame) -> FrameResult:
        self.located += 1
        return super().locate(posed)


def test_a_posed_frame_out_of_time_order_is_refused_before_its_people_are_located() -> None:
    frames = list(SyntheticSource("S1", frames=4))
    stream = PeopleStream(CountingPipeline(TruthPose()))
    for frame in frames:
        last = stream.update_posed(stream.pipeline.pose_frame(frame))
    late = replace(frames[1], index=4)
    with pytest.raises(TrackingError, match="frame 4 is out of time order"):
        stream.update_posed(stream.pipeline.pose_frame(late))
    assert stream.pipeline.located == 4  # type: ignore[attr-defined]
    after = stream.update(replace(frames[3], index=5, timestamp=frames[3].timestamp + 0.1))
    assert {p.id for p in after.tracks.people} == {p.id for p in last.tracks.people} and after.tracks.reset is None

"""People and groups over time: the streaming object on a built-in moving sequence.

Two people walk in file, then two side by side, past a robot's camera (``synthetic:walking_pairs``). One
``SocialStream.update`` per frame runs the per-frame pipeline (here ``TruthPose``: the rendered keypoints with
detector-like noise), the people and group trackers and the costmap. Once a second it prints each reported track
(map frame, m and m/s) and the tracked groups: walkers come out as a ``walking`` group, never as a conversation.
"""

from __future__ import annotations

from costmap.grid import GridSpec
from sid.perception.pipeline import Pipeline
from sid.sources.synthetic import SyntheticSource
from sid.stream import SocialStream
from sid.synthetic.pose import TruthPose

source = SyntheticSource("synthetic:walking_pairs", seed=0, fps=5)  # 5 frames a second: quick to render
pipeline = Pipeline(TruthPose(), source.scene.mount, group=False)  # the group tracker groups the tracks itself
grid = GridSpec.from_size(0.05, (-2.0, -6.0), (12.0, 12.0))  # 12 m x 12 m of the map, 5 cm cells
stream = SocialStream(pipeline, grid)
fps = source.camera.fps

for frame in source:
    update = stream.update(frame)  # the frame carries the robot's pose: everything is in the map frame
    if frame.index % round(fps) or not update.people:
        continue
    print(f"t = {update.timestamp:4.1f} s ({update.frame_id}), costmap {update.timing_ms['costmap']:.1f} ms")
    for p in update.people:
        print(f"  track {p.id}: ({p.x:5.2f}, {p.y:5.2f}) m, velocity ({p.vx:5.2f}, {p.vy:5.2f}) m/s, {p.state}")
    for g in update.groups:
        print(f"  group {g.id}: {g.kind}, members {list(g.members)}")
    costs = update.costmap.costs  # the combined uint8 grid (Nav2 values), rows along map y
    print(f"  costmap: {int((costs > 0).sum())} of {costs.size} cells with a cost")

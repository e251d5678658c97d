"""``sid simulate``: the paper's navigation experiment as a closed loop, with the camera, the LiDAR, perception,
tracking, the costmap, replanning and a path follower in it (docs/simulate.md).

Modules: ``world`` (scene files, people's motion, collisions), ``scenes`` (the built-in scenes), ``robot`` (the
differential drive), ``perception`` (what the robot learns per step, and its costmap update), ``follower`` (regulated
pure pursuit: path and pose to a velocity command), ``loop`` (one run), ``metrics`` (measured on the driven
trajectory), ``video`` (frames, MP4, GIF), ``run`` (one run and its files), ``sweep`` (many runs: worker processes or
Ray), ``report`` (the sweep's table, JSON and chart).
"""

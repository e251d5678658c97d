"""Perception: records (frames, calibration, people, groups) and the algorithms that fill them, per frame.

The bottom layer of sid: it imports nothing from ``costmap``, ``planner`` or sid's orchestration packages.
"""

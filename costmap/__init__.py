"""Layered 2D costmap in Nav2's conventions: a Layer interface, static, LiDAR, social and inflation layers, exports."""

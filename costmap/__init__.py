"""Layered 2D costmap in Nav2's conventions: a LiDAR base, inflation and social zones, with exports."""

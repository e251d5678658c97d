"""Costmap layers, one class each (Nav2's plugins): static map, obstacles (LiDAR), inflation, social zones."""

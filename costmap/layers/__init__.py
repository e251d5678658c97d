"""Costmap layers, one ``costmap.layer.Layer`` class each (Nav2's plugins): static map, obstacles (LiDAR), social
zones, inflation."""

"""Scenario files (a map, obstacles, people and a robot task) and what is built from them: costmaps, plans."""

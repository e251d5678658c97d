"""The costmap benchmark's scene."""

from __future__ import annotations

from sid.experiments.bench.scenes import bench_scene


def test_bench_scene_groups_are_made_of_its_people():
    _, people, groups = bench_scene()
    ids = {p.id for p in people}
    assert [len(g.members) for g in groups] == [3, 4, 3]
    assert all(set(g.members) <= ids for g in groups)

"""The costmap benchmark runs and reports every median it promises (timings are reported, never asserted)."""

from __future__ import annotations

from costmap.bench import bench_costmap_update, bench_scene


def test_bench_reports_all_medians():
    result = bench_costmap_update(repeats=1)
    assert result["map_cells"] == 400 * 400 and result["beams"] == 720
    assert result["groups"] == 3 and result["people"] == 10
    for key in (
        "update_ms",
        "update_baseline_ms",
        "scan_sim_ms",
        "lidar_ms",
        "social_ms",
        "inflation_opencv_ms",
        "inflation_scipy_ms",
    ):
        assert result[key] > 0


def test_bench_scene_groups_are_made_of_its_people():
    _, people, groups = bench_scene()
    ids = {p.id for p in people}
    assert [len(g.members) for g in groups] == [3, 4, 3]
    assert all(set(g.members) <= ids for g in groups)

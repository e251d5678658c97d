"""``sid bench``'s tracking stages write what they measured (people, groups, parts); never how fast."""

from __future__ import annotations

from sid.cli import main
from sid.experiments.bench import load_report


def test_track_stages_report_their_people_groups_and_parts(tmp_path):
    out = tmp_path / "bench"
    assert main(["bench", "--quick", "--only", "track/4,track/20", "--out", str(out)]) == 0
    stages = load_report(out / "bench.json")["stages"]
    assert stages["track/4"]["people"] == 4 and stages["track/4"]["groups"] == 1
    assert stages["track/20"]["people"] == 20 and stages["track/20"]["groups"] == 5
    for n in (4, 20):
        for part in ("people", "groups", "layer"):
            stage = stages[f"track/{n}/{part}"]
            assert stage["runs"] >= 1 and 0 <= stage["min_ms"] <= stage["median_ms"] <= stage["max_ms"]

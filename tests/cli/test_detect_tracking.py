"""``sid detect`` with tracking (the default) and with ``--no-tracking``."""

from __future__ import annotations

import json

from sid.cli import main


def _lines(text: str) -> list[dict]:
    return [json.loads(line) for line in text.splitlines() if line.startswith("{")]


def test_detect_reports_tracks_with_stable_ids_velocities_and_groups(capsys) -> None:
    assert main(["detect", "--source", "synthetic:S1", "--frames", "14", "--no-keypoints"]) == 0
    records = _lines(capsys.readouterr().out)
    assert len(records) == 14 and all(r["frame_id"] == "base_footprint" for r in records)
    assert records[0]["people"] == []  # a track is reported from its third detection on
    ids = [sorted(p["id"] for p in r["people"]) for r in records[2:]]
    assert all(i == ids[0] for i in ids) and len(ids[0]) == 2
    person = records[-1]["people"][0]
    assert set(person) == {"id", "x", "y", "theta", "orientation_quality", "velocity", "state", "visible"}
    assert person["state"] == "standing" and len(person["velocity"]) == 2 and person["visible"]
    (group,) = records[-1]["groups"]
    assert group["kind"] == "conversation" and group["members"] == ids[0]
    assert {"id", "interest_point", "zone", "velocity"} <= group.keys()
    assert len({r["groups"][0]["id"] for r in records if r["groups"]}) == 1
    assert {"track", "track_groups"} <= records[-1]["timing_ms"].keys()
    assert "group" not in records[-1]["timing_ms"]  # the frame's own grouping, unused with tracking, is skipped


def test_the_summary_and_the_total_time_are_those_of_the_printed_tracks(capsys) -> None:
    """With tracking, the first two frames print ``people: []`` (no track confirmed yet): the summary counted them
    as frames with people. Each line's ``timing_ms.total`` left the trackers out, though SocialStream's counts them."""
    assert main(["detect", "--source", "synthetic:S1", "--frames", "4", "--no-keypoints"]) == 0
    captured = capsys.readouterr()
    records = _lines(captured.out)
    assert [len(r["people"]) for r in records] == [0, 0, 2, 2]
    assert "detect: 2 frames with people, 2 frames with no track reported yet (people: []), 0 skipped" in captured.err
    for record in records:
        timing = record["timing_ms"]
        assert list(timing)[-1] == "total" and {"track", "track_groups"} <= timing.keys()
        assert abs(timing["total"] - sum(v for k, v in timing.items() if k != "total")) < 0.01


def test_detect_keeps_each_persons_keypoints_from_the_matched_detection(capsys) -> None:
    assert main(["detect", "--source", "synthetic:S1", "--frames", "4"]) == 0
    record = _lines(capsys.readouterr().out)[-1]
    assert all(len(p["keypoints"]) == 17 for p in record["people"])


def test_no_tracking_gives_each_frames_own_detections(capsys) -> None:
    assert main(["detect", "--source", "synthetic:S1", "--frames", "2", "--no-tracking", "--no-keypoints"]) == 0
    records = _lines(capsys.readouterr().out)
    for record in records:
        assert sorted(p["id"] for p in record["people"]) == [0, 1]
        assert "velocity" not in record["people"][0] and "id" not in record["groups"][0]
        assert "group" in record["timing_ms"]


def test_pictures_draw_the_records_of_the_json_line(tmp_path, capsys, monkeypatch) -> None:
    """Every frame's overlay labels and top view hold the people (track ids) and groups of its JSON line."""
    from sid.cli import detect

    drawn: dict[int, detect.PictureRecords] = {}
    draw = detect._pictures

    def spy(frame, result, records, mount):  # type: ignore[no-untyped-def]
        drawn[frame.index] = records
        return draw(frame, result, records, mount)

    monkeypatch.setattr(detect, "_pictures", spy)
    arguments = ["--source", "synthetic:crossing_walkers", "--frames", "40", "--no-keypoints"]
    assert main(["detect", *arguments, "--out", str(tmp_path)]) == 0
    records = _lines(capsys.readouterr().out)
    assert len(records) == len(drawn) == 40
    assert any(r["people"] for r in records) and any(r["groups"] for r in records)
    assert any(not r["people"] for r in records)  # the first frames, before a track is confirmed
    for record, (index, pictured) in zip(records, sorted(drawn.items()), strict=True):
        ids = sorted(p["id"] for p in record["people"])
        assert sorted(p.id for p in pictured.people) == ids, index
        assert {p.id for p in pictured.labels if p is not None} <= set(ids), index
        assert [list(g.members) for g in pictured.groups] == [g["members"] for g in record["groups"]], index
        assert (tmp_path / f"overlay_{index:06d}.png").exists() and (tmp_path / f"topview_{index:06d}.png").exists()


def test_a_frame_out_of_time_order_is_skipped_and_the_tracks_go_on(capsys, monkeypatch) -> None:
    """A frame the trackers refuse (its timestamp repeats an earlier one) is reported and skipped; the tracks and
    their ids carry on through the frames after it as if it had not come."""
    from dataclasses import replace

    from sid.cli import detect
    from sid.sources.synthetic import SyntheticSource

    frames = list(SyntheticSource("S1", frames=8))
    frames[5] = replace(frames[5], timestamp=frames[3].timestamp)
    monkeypatch.setattr(detect, "open_source", lambda spec, **options: iter(frames))
    assert main(["detect", "--source", "synthetic:S1", "--no-keypoints"]) == 0
    captured = capsys.readouterr()
    records = _lines(captured.out)
    assert [r["frame"] for r in records] == [0, 1, 2, 3, 4, 6, 7]
    assert "detect: frame 5: skipped, frame 5 is out of time order" in captured.err
    assert "5 frames with people, 2 frames with no track reported yet (people: []), 1 skipped" in captured.err
    ids = [sorted(p["id"] for p in r["people"]) for r in records[2:]]
    assert all(i == ids[0] for i in ids) and len(ids[0]) == 2


def test_the_files_written_are_named_on_stderr_and_stdout_stays_json(tmp_path, capsys) -> None:
    assert main(["detect", "--source", "synthetic:S1", "--frames", "3", "--out", str(tmp_path)]) == 0
    captured = capsys.readouterr()
    assert all(line.startswith("{") for line in captured.out.splitlines())
    wrote = f"detect: wrote {tmp_path / 'detections.jsonl'} and 3 overlay_*.png, 3 topview_*.png beside it"
    assert captured.err.splitlines()[-1] == wrote
    assert len(list(tmp_path.glob("overlay_*.png"))) == len(list(tmp_path.glob("topview_*.png"))) == 3


def test_session_options_without_a_model_are_refused_not_ignored(capsys) -> None:
    # A synthetic source without --model runs its true poses: --provider and --threads would change nothing.
    for option in (["--provider", "openvino"], ["--threads", "1"], ["--contract", "yolo"]):
        assert main(["detect", "--source", "synthetic:S1", "--frames", "2", *option]) == 2
        assert f"detect: {option[0]}: an option of the pose model's session, and there is no --model" in (
            capsys.readouterr().err
        )


def test_a_parameters_file_sets_the_trackers_and_the_group_detector(tmp_path, capsys) -> None:
    params = tmp_path / "robot.yaml"
    params.write_text("tracking:\n  tracker:\n    confirm_hits: 1\ngroups:\n  group_price: 100.0\n")
    arguments = ["--source", "synthetic:S1", "--frames", "14", "--no-keypoints", "--params", str(params)]
    assert main(["detect", *arguments]) == 0
    records = _lines(capsys.readouterr().out)
    assert all(len(r["people"]) == 2 for r in records)  # confirmed at the first detection (the default: the third)
    assert all(r["groups"] == [] for r in records)  # a group priced above two people alone is never worth it
    assert main(["detect", *arguments, "--group-price", "0.8"]) == 0  # the option wins over the file
    assert _lines(capsys.readouterr().out)[-1]["groups"] != []


def test_a_bad_parameters_file_stops_detect_before_the_source_opens(tmp_path, capsys) -> None:
    params = tmp_path / "robot.yaml"
    params.write_text("tracking:\n  tracker:\n    timeout: -1\n")
    assert main(["detect", "--source", "synthetic:S1", "--params", str(params)]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert (
        captured.err
        == f"detect: {params}: tracking.tracker: timeout must be a finite number of seconds >= 0, got -1.0\n"
    )

"""``sid track``: the people and group trackers on JSON lines of detections."""

from __future__ import annotations

import io
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from sid.cli import main
from tests.conftest import REPO_ROOT

FPS = 15
PAIR_SPEED = 1.2  # m/s along +x
TRIO_CENTRE = (4.0, -1.0)


def scene(steps: int, seed: int = 0) -> tuple[list[dict], list[dict[int, int]]]:
    """``steps`` input lines at 15 fps of two people walking side by side (0.6 m apart, 1.2 m/s along +x) and three
    standing in conversation around TRIO_CENTRE (0.7 m away, facing it), with 2 cm / 0.05 rad of noise and the
    people in a new order on each line. The walkers carry a new detector id on each line, the others none (their
    index). Also, per line, the true person (0-4: walkers 0 and 1) behind each detection id."""
    rng = np.random.default_rng(seed)
    lines, truth = [], []
    for step in range(steps):
        t = step / FPS
        true = [(PAIR_SPEED * t, 2.0 + 0.6 * k, 0.0) for k in range(2)]
        for k in range(3):
            angle = 2 * math.pi * k / 3
            true.append(
                (TRIO_CENTRE[0] + 0.7 * math.cos(angle), TRIO_CENTRE[1] + 0.7 * math.sin(angle), angle + math.pi)
            )
        people, behind = [], {}
        for index, who in enumerate(rng.permutation(5).tolist()):
            x, y, theta = true[who]
            person = {"x": x + rng.normal(0, 0.02), "y": y + rng.normal(0, 0.02), "theta": theta + rng.normal(0, 0.05)}
            if who < 2:
                person["id"] = 1000 * step + 10 * who + 7
            behind[person.get("id", index)] = who
            people.append(person)
        lines.append({"timestamp": round(t, 4), "people": people})
        truth.append(behind)
    return lines, truth


def write_lines(path: Path, lines: list[dict | str]) -> Path:
    path.write_text("".join((line if isinstance(line, str) else json.dumps(line)) + "\n" for line in lines))
    return path


def run_sid(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, list[dict], list[str]]:
    code = main(argv)
    captured = capsys.readouterr()
    return code, [json.loads(line) for line in captured.out.splitlines()], captured.err.splitlines()


def test_a_walking_pair_and_a_standing_conversation_are_tracked_with_stable_ids(tmp_path, capsys):
    lines, truth = scene(30)
    code, out, err = run_sid(["track", str(write_lines(tmp_path / "in.jsonl", lines))], capsys)
    assert code == 0 and err == [] and len(out) == 30
    assert [record["timestamp"] for record in out] == [line["timestamp"] for line in lines]
    assert out[0]["people"] == out[1]["people"] == []  # a track is reported from its third detection
    person_of_track: dict[int, int] = {}
    for record, behind in zip(out[2:], truth[2:], strict=True):
        assert set(record) == {"timestamp", "people", "groups", "timing_ms"}
        assert set(record["timing_ms"]) == {"track", "track_groups"}
        assert len(record["people"]) == 5
        for person in record["people"]:
            assert set(person) == {
                "id",
                "x",
                "y",
                "theta",
                "orientation_quality",
                "velocity",
                "state",
                "visible",
                "detection",
            }
            assert person["visible"] and person["detection"] in behind
            # the same track id stays with the same person on every line
            assert person_of_track.setdefault(person["id"], behind[person["detection"]]) == behind[person["detection"]]
    assert sorted(person_of_track.values()) == [0, 1, 2, 3, 4]
    track_of = {who: track for track, who in person_of_track.items()}
    pair, trio = sorted(track_of[k] for k in (0, 1)), sorted(track_of[k] for k in (2, 3, 4))

    last = {person["id"]: person for person in out[-1]["people"]}
    for track in pair:
        assert last[track]["state"] == "walking"
        assert last[track]["velocity"] == pytest.approx([PAIR_SPEED, 0.0], abs=0.1)
        assert last[track]["x"] == pytest.approx(PAIR_SPEED * lines[-1]["timestamp"], abs=0.1)
    for track in trio:
        assert last[track]["state"] == "standing" and last[track]["velocity"] == pytest.approx([0, 0], abs=0.1)

    # Both groups are found within the first second and kept, with one id each, to the end.
    groups = [{(g["kind"], tuple(g["members"])): g for g in record["groups"]} for record in out]
    walking, conversation = ("walking", tuple(pair)), ("conversation", tuple(trio))
    assert all(set(found) == {walking, conversation} for found in groups[FPS:])
    assert len({found[walking]["id"] for found in groups[FPS:]}) == 1
    assert len({found[conversation]["id"] for found in groups[FPS:]}) == 1
    assert not any(kind == "conversation" and set(members) & set(pair) for found in groups for kind, members in found)
    circle = groups[-1][conversation]
    assert circle["interest_point"] == pytest.approx(TRIO_CENTRE, abs=0.1) and circle["zone"]
    assert groups[-1][walking]["velocity"] == pytest.approx([PAIR_SPEED, 0.0], abs=0.1)
    assert groups[-1][walking]["zone"] == []


BAD_LINES = [
    ("{not json", "not valid JSON (Expecting property name enclosed in double quotes at character 2 of the line)"),
    ("[1, 2]", "expected a JSON object with 'timestamp' and 'people'"),
    ('{"people": []}', "missing 'timestamp'"),
    ('{"timestamp": "0.5", "people": []}', "'timestamp' must be a finite number of seconds, got \"0.5\""),
    ('{"timestamp": 1e400, "people": []}', "'timestamp' must be a finite number of seconds, got Infinity"),
    ('{"timestamp": NaN, "people": []}', "not valid JSON (NaN is not a number)"),
    ('{"timestamp": 0.5, "people": {}}', "'people' must be a list"),
    ('{"timestamp": 0.5, "people": [3]}', "people[0] must be an object with id, x, y, theta, orientation_quality"),
    ('{"timestamp": 0.5, "people": [{"y": 0}]}', "people[0] (id 0) is missing 'x'"),
    (
        '{"timestamp": 0.5, "people": [{"x": 0, "y": null}]}',
        "people[0] (id 0): y must be a finite number of metres, got null",
    ),
    (
        '{"timestamp": 0.5, "people": [{"x": 0, "y": 1' + "0" * 400 + "}]}",  # an int no float can hold
        "people[0] (id 0): y must be a finite number of metres, got 1" + "0" * 76 + "...",  # its summary, 80 characters
    ),
    (
        '{"timestamp": 0.5, "people": [{"x": 0, "y": 0, "theta": "north"}]}',
        'people[0] (id 0): theta must be a finite number of radians, or null when unknown, got "north"',
    ),
    (
        '{"timestamp": 0.5, "people": [{"x": 0, "y": 0, "thta": 1.0}]}',
        "people[0]: unknown field 'thta' (the fields are id, x, y, theta, orientation_quality)",
    ),
    ('{"timestamp": 0.5, "frame": 3, "people": []}', "unknown field 'frame' (the fields are timestamp, people)"),
    ('{"timestamp": 0.5, "people": [{"x": 0, "x": 1, "y": 0}]}', "not valid JSON (duplicate key 'x')"),
    ('{"timestamp": 0.5, "people": [{"id": 1.5, "x": 0, "y": 0}]}', "people[0]: id must be an integer, got 1.5"),
    (
        '{"timestamp": 0.5, "people": [{"id": 4, "x": 0, "y": 0}, {"id": 4, "x": 1, "y": 0}]}',
        "people[0] and people[1] have one id, 4",
    ),
]


def test_malformed_lines_are_reported_with_their_number_and_skipped(tmp_path, capsys):
    good = [{"timestamp": 0.0, "people": [{"x": 1.0, "y": 0.0}]}, {"timestamp": 0.5, "people": [{"x": 1.0, "y": 0.0}]}]
    source = write_lines(tmp_path / "in.jsonl", [good[0], *(line for line, _ in BAD_LINES), "", good[1]])
    code, out, err = run_sid(["track", str(source)], capsys)
    assert code == 0 and [record["timestamp"] for record in out] == [0.0, 0.5]
    expected = [f"sid track: line {number}: {problem}" for number, (_, problem) in enumerate(BAD_LINES, start=2)]
    assert err == [*expected, f"sid track: skipped {len(BAD_LINES)} malformed lines"]


def test_too_many_people_in_a_line_are_refused_by_the_people_limit(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("SID_LIMITS", "people=2")
    source = write_lines(tmp_path / "in.jsonl", [{"timestamp": 0, "people": [{"x": k, "y": 0} for k in range(3)]}])
    code, out, err = run_sid(["track", str(source)], capsys)
    assert code == 2 and out == []  # no line was good
    assert err[0] == (
        "sid track: line 1: people: 3 people is more than the limit of 2 people (people; raise it with "
        "SID_LIMITS=people=N)"
    )


def test_strict_stops_at_the_first_bad_line_keeping_earlier_output(tmp_path, capsys):
    lines, _ = scene(5)
    source = write_lines(tmp_path / "in.jsonl", [*lines[:4], '{"timestamp": 9, "people": [{"x": 0}]}', lines[4]])
    code, out, err = run_sid(["track", "--strict", str(source)], capsys)
    assert code == 2 and [record["timestamp"] for record in out] == [line["timestamp"] for line in lines[:4]]
    assert len(out[-1]["people"]) == 5
    assert err == ["sid track: line 5: people[0] (id 0) is missing 'y'"]


def test_timestamps_out_of_order_are_refused_naming_both(tmp_path, capsys):
    one = [{"x": 1.0, "y": 0.0}]
    twice = [{"id": 1, "x": 1.0, "y": 0.0}, {"id": 1, "x": 2.0, "y": 0.0}]
    lines = [
        {"timestamp": 1.0, "people": one},
        {"timestamp": 0.5, "people": one},
        {"timestamp": 1.0, "people": one},
        {"timestamp": 3.0, "people": twice},  # refused: its timestamp does not count as the last good one
        {"timestamp": 2.0, "people": one},
    ]
    code, out, err = run_sid(["track", str(write_lines(tmp_path / "in.jsonl", lines))], capsys)
    assert code == 0 and [record["timestamp"] for record in out] == [1.0, 2.0]
    assert err == [
        "sid track: line 2: frame is out of time order: its timestamp 0.5 s is not after the last one, 1.0 s",
        "sid track: line 3: frame is out of time order: its timestamp 1.0 s is not after the last one, 1.0 s",
        "sid track: line 4: people[0] and people[1] have one id, 1",
        "sid track: skipped 3 malformed lines",
    ]


def test_group_detector_options_are_checked(capsys, monkeypatch):
    monkeypatch.setattr(sys, "stdin", io.StringIO(""))
    code, out, err = run_sid(["track", "-", "--eps", "-1"], capsys)
    assert code == 2 and out == [] and err == ["sid track: groups: eps must be a positive number of metres, got -1.0"]


def test_unreadable_input_is_one_line(tmp_path, capsys):
    code, out, err = run_sid(["track", str(tmp_path / "missing.jsonl")], capsys)
    assert (
        code == 2
        and out == []
        and err == [f"sid track: cannot read {tmp_path / 'missing.jsonl'}: No such file or directory"]
    )
    code, out, err = run_sid(["track", str(tmp_path)], capsys)
    assert code == 2 and out == [] and err == [f"sid track: cannot read {tmp_path}: it is a folder, not a regular file"]


def test_stdin_is_read_as_bytes_line_by_line():
    lines, _ = scene(4)
    lines[3]["people"][0]["theta"] = None  # an unknown facing
    data = b"\xef\xbb\xbf" + "\n".join(json.dumps(line) for line in lines[:3]).encode() + b"\n\xff\n"
    data += json.dumps(lines[3]).encode() + b"\n"
    done = subprocess.run(
        [sys.executable, "-m", "sid", "track", "-"], input=data, capture_output=True, cwd=REPO_ROOT, timeout=60
    )
    assert done.returncode == 0
    records = [json.loads(line) for line in done.stdout.splitlines()]
    assert [record["timestamp"] for record in records] == [line["timestamp"] for line in lines]
    assert len(records[-1]["people"]) == 5
    assert done.stderr.decode().splitlines() == [
        "sid track: line 4: not UTF-8 text (byte 0xff at byte 1 of the line)",
        "sid track: skipped 1 malformed line",
    ]


def test_a_reader_that_goes_away_ends_the_run_quietly(tmp_path):
    lines, _ = scene(300)
    source = write_lines(tmp_path / "in.jsonl", lines)
    process = subprocess.Popen(
        [sys.executable, "-m", "sid", "track", str(source)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        cwd=REPO_ROOT,
    )
    assert process.stdout and process.stderr
    assert json.loads(process.stdout.readline())["timestamp"] == 0.0  # flushed at once, as `| head -1` reads it
    process.stdout.close()
    assert process.wait(timeout=60) == 0
    assert process.stderr.read() == b""


def test_help_describes_the_input_and_output(capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["track", "--help"])
    assert exit_info.value.code == 0
    text = capsys.readouterr().out
    assert text.startswith("usage: sid track [-h] [--strict]")
    for needle in ('"timestamp"', '"detection"', "theta null or absent", "REP-103", "--strict", "--method", "FILE"):
        assert needle in text


def test_a_facing_in_degrees_by_mistake_is_a_malformed_line(tmp_path, capsys):
    """theta 90 read as radians points anywhere: a yaw beyond two turns is refused, naming the unit."""
    lines = [{"timestamp": 0.0, "people": [{"x": 1.0, "y": 0.0, "theta": 1.5}]}]
    lines.append({"timestamp": 0.1, "people": [{"x": 1.0, "y": 0.0, "theta": -90}]})
    code, out, err = run_sid(["track", str(write_lines(tmp_path / "in.jsonl", lines))], capsys)
    assert code == 0 and [record["timestamp"] for record in out] == [0.0]
    assert err[0] == (
        "sid track: line 2: people[0] (id 0): theta -90 is beyond two turns (4 pi): radians expected, not degrees"
    )


def test_a_gap_that_ends_every_track_is_noted_so_timestamps_in_another_unit_are_not_silent(tmp_path, capsys):
    """Timestamps in nanoseconds (a ROS stamp) put 33 000 000 "s" between frames: every track times out before the
    next frame, and nobody was ever reported, without a word. Each gap longer than the tracker's timeout that ends
    tracks is now noted on stderr (the line still tracked), once for lines in a row that all do it; a gap with no track
    alive, the first line, is not."""
    step = [{"x": 1.0, "y": 0.0}, {"x": 2.0, "y": 1.0}]
    lines = [{"timestamp": 1_700_000_000_000_000_000 + k * 33_000_000, "people": step} for k in range(3)]
    code, out, err = run_sid(["track", str(write_lines(tmp_path / "ns.jsonl", lines))], capsys)
    assert code == 0 and len(out) == 3 and all(record["people"] == [] for record in out)
    assert err == [  # once for the run of such lines, not at every line
        "sid track: line 2: note: 3.3e+07 s after the last frame, more than the tracker's timeout (1.5 s): every "
        "track in view that it missed ended (are the timestamps in seconds?); the frames right after it that do the "
        "same are not noted"
    ]
    pause = [{"timestamp": t, "people": step} for t in (0.0, 0.1, 0.2, 10.2, 10.3)]
    pause.insert(3, {"timestamp": 5.0, "people": []})  # tracks alive, none detected: they end at the next line
    code, out, err = run_sid(["track", str(write_lines(tmp_path / "pause.jsonl", pause))], capsys)
    assert code == 0 and [len(record["people"]) for record in out] == [0, 0, 2, 0, 0, 0]
    assert err == [
        "sid track: line 4: note: 4.8 s after the last frame, more than the tracker's timeout (1.5 s): every track "
        "in view that it missed ended (are the timestamps in seconds?); the frames right after it that do the same "
        "are not noted"
    ]


def test_a_line_stamped_in_the_future_does_not_stop_the_tracking_for_good(tmp_path, capsys):
    """One line stamped in milliseconds among lines in seconds: every line after it was refused as out of time order
    (749 of 900 in a probe), and a looped recording lost every loop after the first. Time going back more than
    max_time_back (1 s) now starts the trackers over, with a note; less than that is still refused."""
    step = [{"x": 1.0, "y": 0.0}, {"x": 2.0, "y": 1.0}]
    stamps = [1.7e9 + 0.25 * k for k in range(5)]
    stamps[2] *= 1000
    stamps += [stamps[-1] - 0.5]  # a line 0.5 s late: out of order, refused
    lines = [{"timestamp": t, "people": step} for t in stamps]
    code, out, err = run_sid(["track", str(write_lines(tmp_path / "glitch.jsonl", lines))], capsys)
    assert code == 0 and [len(record["people"]) for record in out] == [0, 2, 0, 0, 2]
    assert err[1:] == [
        "sid track: line 4: note: time went back 1.7e+12 s: the trackers started over",
        "sid track: line 6: frame is out of time order: its timestamp 1700000000.5 s is not after the last one, "
        "1700000001.0 s",
        "sid track: skipped 1 malformed line",
    ]


def test_an_id_given_twice_names_both_people_and_a_default_id(tmp_path, capsys):
    """A person without an id takes its index: beside an explicit id 1 at index 0, the person at index 1 collided
    with it under 'person id 1 appears twice', an id the line gives once."""
    lines = [
        {"timestamp": 0.0, "people": [{"id": 1, "x": 0.0, "y": 0.0}, {"x": 1.0, "y": 0.0}]},
        {
            "timestamp": 0.1,
            "people": [{"id": 4, "x": 0.0, "y": 0.0}, {"x": 1.0, "y": 0.0}, {"id": 4, "x": 2.0, "y": 0.0}],
        },
    ]
    code, out, err = run_sid(["track", str(write_lines(tmp_path / "in.jsonl", lines))], capsys)
    assert code == 2 and out == []  # no line was good
    assert err[:2] == [
        "sid track: line 1: people[0] and people[1] have one id, 1 (people[1] has no 'id': its index in the list is "
        "its id)",
        "sid track: line 2: people[0] and people[2] have one id, 4",
    ]


def test_people_without_facings_make_conversations_with_positions_only_groups(tmp_path, capsys):
    # A LiDAR leg tracker's detections: positions only. Three people standing 1 m apart, a fourth 4 m away.
    people = [{"x": 2.0, "y": 0.5}, {"x": 2.0, "y": -0.5}, {"x": 2.9, "y": 0.0}, {"x": 6.0, "y": 3.0}]
    source = write_lines(tmp_path / "in.jsonl", [{"timestamp": k / FPS, "people": people} for k in range(20)])
    code, out, _ = run_sid(["track", str(source), "--positions-only-reach", "1"], capsys)
    by_position = {(p["x"], p["y"]): p["id"] for p in out[-1]["people"]}
    [group] = out[-1]["groups"]
    assert code == 0 and group["kind"] == "conversation"
    assert sorted(group["members"]) == sorted(by_position[(p["x"], p["y"])] for p in people[:3])
    assert group["interest_point"] == pytest.approx([2.3, 0.0])
    code, out, _ = run_sid(["track", str(source)], capsys)
    assert code == 0 and out[-1]["groups"] == []  # off by default


def test_a_parameters_file_sets_the_trackers_and_the_group_detector_and_options_win_over_it(tmp_path, capsys):
    # The same LiDAR-like scene: with the file, tracks confirmed at their first detection and groups from positions.
    people = [{"x": 2.0, "y": 0.5}, {"x": 2.0, "y": -0.5}, {"x": 2.9, "y": 0.0}, {"x": 6.0, "y": 3.0}]
    source = write_lines(tmp_path / "in.jsonl", [{"timestamp": k / FPS, "people": people} for k in range(20)])
    params = tmp_path / "leg_detector.yaml"
    params.write_text("groups:\n  positions_only_reach: 1.0\ntracking:\n  tracker:\n    confirm_hits: 1\n")
    code, out, _ = run_sid(["track", str(source)], capsys)
    assert code == 0 and out[0]["people"] == [] and out[-1]["groups"] == []  # the defaults
    code, out, _ = run_sid(["track", str(source), "--params", str(params)], capsys)
    assert code == 0 and len(out[0]["people"]) == 4 and len(out[-1]["groups"]) == 1
    code, out, _ = run_sid(["track", str(source), "--params", str(params), "--positions-only-reach", "0"], capsys)
    assert code == 0 and len(out[0]["people"]) == 4 and out[-1]["groups"] == []


def test_a_bad_parameters_file_is_one_line_naming_the_file_and_the_field(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(sys, "stdin", io.StringIO(""))
    params = tmp_path / "p.yaml"
    params.write_text("tracking:\n  tracker:\n    timeout: soon\n")
    code, out, err = run_sid(["track", "-", "--params", str(params)], capsys)
    assert code == 2 and out == []
    assert err == [f'sid track: {params}: tracking.tracker.timeout: expected a finite number, got "soon"']
    code, out, err = run_sid(["groups", "-", "--params", str(tmp_path / "nowhere.yaml")], capsys)
    assert code == 2 and out == [] and len(err) == 1 and "nowhere.yaml: cannot read parameters file" in err[0]


def test_input_of_which_no_line_is_good_exits_2_and_one_good_line_is_enough(tmp_path, capsys):
    # sid detect's lines (a "frame" field) are not sid track's: every line refused, nothing written. A script must
    # not read that as an empty result (exit 0 until then); an input with one good line among bad ones exits 0.
    bad = {"frame": 0, "timestamp": 0.0, "people": []}
    code, out, err = run_sid(["track", str(write_lines(tmp_path / "bad.jsonl", [bad, bad]))], capsys)
    assert code == 2 and out == [] and err[-1] == "sid track: skipped 2 malformed lines, and no line was good"
    good = {"timestamp": 1.0, "people": []}
    code, out, err = run_sid(["track", str(write_lines(tmp_path / "mixed.jsonl", [bad, good]))], capsys)
    assert code == 0 and len(out) == 1 and err[-1] == "sid track: skipped 1 malformed line"
    code, out, err = run_sid(["groups", str(write_lines(tmp_path / "empty.jsonl", []))], capsys)
    assert (code, out, err) == (0, [], [])

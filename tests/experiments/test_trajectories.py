"""Reading trajectory sets (obsmat.txt + groups.txt) and replaying them as detections."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from sid.experiments.trajectories import (
    ReplaySettings,
    TrajectoryError,
    load_trajectory_set,
    replay,
)
from sid.tracking import ViewCone
from tests.conftest import shared_path
from tests.experiments.trajectory_files import write_set


def _walkers(frames: int = 5, step: int = 10) -> list[tuple[float, ...]]:
    """Pedestrians 1 and 2 side by side along +x at 1 m/s, 3 alone going -x; one row per 0.4 s step."""
    rows = []
    for k in range(frames):
        x = 0.4 * k
        rows += [
            (k * step, 1, x, 0, 0.0, 1, 0, 0),
            (k * step, 2, x, 0, 0.6, 1, 0, 0),
            (k * step, 3, 5 - x, 0, 3, -1, 0, 0),
        ]
    return rows


def test_a_set_is_read_into_frames_with_times_positions_and_groups(tmp_path: Path) -> None:
    folder = write_set(tmp_path / "pairs", _walkers(), "1 2\n")
    trajectories = load_trajectory_set(folder)
    assert trajectories.name == "pairs" and trajectories.people == 3
    assert trajectories.times.tolist() == pytest.approx([0.0, 0.4, 0.8, 1.2, 1.6])  # frame step 10 = 0.4 s
    assert trajectories.ids[2].tolist() == [1, 2, 3]
    np.testing.assert_allclose(trajectories.positions[2], [[0.8, 0.0], [0.8, 0.6], [4.2, 3.0]])
    assert trajectories.velocities[0].tolist() == [[1, 0], [1, 0], [-1, 0]]
    assert trajectories.groups == (frozenset({1, 2}),)
    assert trajectories.truth_groups({1, 3}) == []  # a group holds while two of its members are present


def test_the_time_between_annotation_steps_is_read_from_positions_and_velocities(tmp_path: Path) -> None:
    """Annotated every 0.1 s (frame step 10 at 100 fps): 0.1 s steps, with a note; 0.4 s steps need no note; nobody
    walking leaves 0.4 s, with a note; a given interval wins."""
    fast = [(10 * k, i, 0.1 * k, 0, y, 1.0, 0, 0) for k in range(8) for i, y in ((1, 0.0), (2, 0.6))]
    folder = write_set(tmp_path / "fast", fast, "1 2\n")
    trajectories = load_trajectory_set(folder)
    assert trajectories.times.tolist() == pytest.approx([0.1 * k for k in range(8)])
    assert trajectories.notes == ("annotations every 0.1 s (frame step 10), read from the annotated positions and "
                                  "velocities (--interval sets it)",)  # fmt: skip
    assert load_trajectory_set(write_set(tmp_path / "usual", _walkers(), "1 2\n")).notes == ()
    standing = [(10 * k, 1, 2.0, 0, 1.0, 0, 0, 0) for k in range(5)]
    still = load_trajectory_set(write_set(tmp_path / "still", standing))
    assert still.times.tolist() == pytest.approx([0.0, 0.4, 0.8, 1.2, 1.6]) and "0.4 s taken" in still.notes[0]
    assert load_trajectory_set(folder, interval=0.2).times.tolist() == pytest.approx([0.2 * k for k in range(8)])


def test_velocities_that_cannot_give_the_time_between_steps_leave_it_at_0_4_s_saying_why(tmp_path: Path) -> None:
    """Velocities in cm/s read as annotations every 0.004 s (MOTA -8.4 on the public sets, named only as that
    interval); velocities all 0 were "too few people walking"."""
    in_cm = [(*row[:5], row[5] * 100, row[6], row[7] * 100) for row in _walkers(frames=8)]
    trajectories = load_trajectory_set(write_set(tmp_path / "cm", in_cm, "1 2\n"))
    assert trajectories.times.tolist() == pytest.approx([0.4 * k for k in range(8)])
    assert trajectories.notes == (
        "the people walking have a median annotated speed of 100, too fast for m/s (velocities in another unit?): "
        "the time between annotation steps is 0.4 s taken (--interval sets it)",
    )
    still = [(*row[:5], 0, 0, 0) for row in _walkers(frames=8)]
    assert load_trajectory_set(write_set(tmp_path / "zero", still, "1 2\n")).notes == (
        "the velocities (v_x, v_y) are all 0: the time between annotation steps is 0.4 s taken (--interval sets it); "
        "at that the people move a median 1 m/s (people walk 1-2 m/s)",
    )


def test_positions_that_move_faster_than_people_walk_are_named_as_another_unit(tmp_path: Path) -> None:
    # Pixels of a top view at 20 px/m: the trackers' gates in metres lost everyone (MOTA 0) without a word.
    in_pixels = [(*row[:2], row[2] * 20, row[3], row[4] * 20, row[5] * 20, row[6], row[7] * 20) for row in _walkers(8)]
    velocities, positions = load_trajectory_set(write_set(tmp_path / "px", in_pixels, "1 2\n")).notes
    assert velocities.startswith("the people walking have a median annotated speed of 20, too fast for m/s")
    assert positions.startswith("the people move a median 20 per second between annotation steps, too fast for metres")
    assert load_trajectory_set(write_set(tmp_path / "m", _walkers(frames=8), "1 2\n")).notes == ()


def test_lines_sharing_a_person_are_one_group_with_a_note(tmp_path: Path) -> None:
    folder = write_set(tmp_path / "s", _walkers(), "1 2\n2 3\n")
    trajectories = load_trajectory_set(folder)
    assert trajectories.groups == (frozenset({1, 2, 3}),)
    assert trajectories.notes == ("groups.txt: lines 1, 2 share people: taken as one group of 3",)


def test_group_members_never_annotated_are_left_out_with_a_note(tmp_path: Path) -> None:
    folder = write_set(tmp_path / "s", _walkers(), "1 2 7\n3 8 9\n")
    trajectories = load_trajectory_set(folder)
    assert trajectories.groups == (frozenset({1, 2}),)  # 3 alone once 8 and 9 are gone: no group
    assert trajectories.notes == (
        "groups.txt:1: pedestrian 7 not in obsmat.txt: left out",
        "groups.txt:2: pedestrians 8, 9 not in obsmat.txt: left out",
    )


def test_an_id_annotated_again_long_after_it_left_is_another_person_with_a_note(tmp_path: Path) -> None:
    """Pedestrian 3 back 22.4 s after leaving (an id reused) is a new person, above every id; pedestrian 1 back
    after 6.4 s is still pedestrian 1. Either way the groups.txt line holds for whoever carries the id."""
    later = [(row[0] + 200, row[1], *row[2:]) for row in _walkers(frames=3) if row[1] == 1]  # 1 again at 8 s
    much_later = [(row[0] + 600, row[1], *row[2:]) for row in _walkers(frames=3) if row[1] == 3]  # 3 at 24 s
    trajectories = load_trajectory_set(write_set(tmp_path / "s", [*_walkers(), *later, *much_later], "1 3\n"))
    assert trajectories.people == 4 and sorted(set(np.concatenate(trajectories.ids).tolist())) == [1, 2, 3, 4]
    back = trajectories.times.tolist().index(pytest.approx(24.0))
    assert trajectories.ids[back].tolist() == [4]  # 3 again, as someone else
    assert trajectories.groups == (frozenset({1, 3, 4}),)
    assert trajectories.notes == (
        "1 pedestrian id annotated again more than 10 s after leaving (longest: pedestrian 3, 22.4 s): each return is "
        "taken as another person (an id reused)",
    )


def test_groups_whose_members_never_come_near_each_other_are_noted_as_other_ids(tmp_path: Path) -> None:
    """Groups.txt numbering people otherwise than obsmat.txt (ids shifted by one) pairs strangers: when a tenth of
    the groups or more (and two or more) never have two members within 2 m of each other, a note asks."""
    rows = _walkers() + [(row[0], row[1] + 3, row[2], 0, row[4] + 10, *row[5:]) for row in _walkers()]
    shifted = load_trajectory_set(write_set(tmp_path / "shifted", rows, "1 3\n4 6\n"))  # 3, 6 walk 3 m away
    assert shifted.notes == (
        "groups.txt: 2 of 2 groups never have two members within 2 m of each other (e.g. pedestrians 1, 3): are its "
        "ids obsmat.txt's?",
    )
    assert load_trajectory_set(write_set(tmp_path / "one", rows, "1 2\n4 6\n")).notes == ()  # one slip: no note


def test_positions_in_x_y_z_column_order_are_refused_naming_the_columns(tmp_path: Path) -> None:
    xyz = [(f, i, x, y, 0.0, vx, vy, 0.0) for f, i, x, _, y, vx, _, vy in _walkers()]  # y in pos_z's column
    with pytest.raises(TrajectoryError, match=r"pos_y \(column 5\) is 0 on every row while pos_z \(column 4\) varies"):
        load_trajectory_set(write_set(tmp_path / "xyz", xyz))


def test_a_groups_file_without_a_group_is_noted(tmp_path: Path) -> None:
    for groups in ("", "\r\n  \n", "7 8\n"):
        trajectories = load_trajectory_set(write_set(tmp_path / "s", _walkers(), groups))
        assert trajectories.groups == ()
        assert trajectories.notes[-1] == (
            "groups.txt holds no group of two or more annotated people: everyone is scored as walking alone"
        )


def test_a_row_written_twice_is_read_once_with_a_note(tmp_path: Path) -> None:
    rows = _walkers()
    folder = write_set(tmp_path / "s", [*rows, rows[4], rows[4], rows[0]], "1 2\n")
    trajectories = load_trajectory_set(folder)
    clean = load_trajectory_set(write_set(tmp_path / "clean", rows, "1 2\n"))
    assert [ids.tolist() for ids in trajectories.ids] == [ids.tolist() for ids in clean.ids]
    assert all(np.array_equal(a, b) for a, b in zip(trajectories.positions, clean.positions, strict=True))
    assert trajectories.notes == ("obsmat.txt: 3 repeated rows read once",)


@pytest.mark.parametrize(
    ("obsmat", "groups", "problem"),
    [
        ("0 1 0 0 0 0 0\n", "", "obsmat.txt:1: 7 columns, expected 8"),
        ("0 1 0 0 0 0 0 nan\n", "", "obsmat.txt:1: a value is not finite"),
        ("0 1 0 0 zero 0 0 0\n", "", "obsmat.txt:1: not numbers"),
        ("0.5 1 0 0 0 0 0 0\n", "", "obsmat.txt:1: frame and pedestrian id must be whole numbers"),
        ("0.4 1 0 0 0 0 0 0\n", "", r"up to 2^53 \(the first column is the frame number, not a time\)$"),
        ("0 1.5 0 0 0 0 0 0\n", "", r"must be whole numbers up to 2^53$"),
        ("0 1e300 0 0 0 0 0 0\n", "", "obsmat.txt:1: frame and pedestrian id must be whole numbers up to 2^53"),
        ("0 1 0 0 -1e9 0 0 0\n", "", r"obsmat.txt:1: position \(0, -1e\+09\) is farther than 1e\+08 m"),
        ("0 1 0 0 0 0 0 0\n0 1 1 0 0 0 0 0\n", "", "obsmat.txt: pedestrian 1 appears twice in frame 0"),
        ("0 1 0 0 0 0 0 0\n0 1 0 0 0 0 0 0\n0 1 1 0 0 0 0 0\n", "", "pedestrian 1 appears twice in frame 0"),
        ("\n\n", "", "obsmat.txt: no annotations"),
        ("0 1 0 0 0 0 0 0\n", "1 two\n", "groups.txt:1: pedestrian ids must be whole numbers"),
        # a CSV export: the separator named
        (
            "0,1,0,0,0,0,0,0\n",
            "",
            "obsmat.txt:1: not numbers: '0,1,0,0,0,0,0,0' .values are separated by spaces or tabs",
        ),
        (
            "0 1 0 0 0 0 0 0\n",
            "1,2\n",
            "groups.txt:1: pedestrian ids must be whole numbers .values are separated by spaces",
        ),
    ],
)
def test_bad_files_are_refused_naming_the_file_line_and_problem(
    tmp_path: Path, obsmat: str, groups: str, problem: str
) -> None:
    (tmp_path / "obsmat.txt").write_text(obsmat)
    (tmp_path / "groups.txt").write_text(groups)
    with pytest.raises(TrajectoryError, match=problem.replace("^", r"\^")):
        load_trajectory_set(tmp_path)


def test_a_missing_file_or_bytes_that_are_not_text_are_refused(tmp_path: Path) -> None:
    with pytest.raises(TrajectoryError, match="no obsmat.txt"):
        load_trajectory_set(tmp_path)
    (tmp_path / "obsmat.txt").write_bytes(b"0 1 0 0 0 0 0 0\n\xff\xfe\n")
    (tmp_path / "groups.txt").write_text("")
    with pytest.raises(TrajectoryError, match="obsmat.txt:2: not UTF-8 text"):
        load_trajectory_set(tmp_path)


def test_a_folder_of_sets_given_as_a_set_names_the_sets_inside(tmp_path: Path) -> None:
    for name in ("zara01", "eth"):
        write_set(tmp_path / "release" / name, _walkers(), "1 2\n")
    with pytest.raises(
        TrajectoryError, match=r"release: no obsmat.txt \(.*\); its sub-folders eth, zara01 do: give them"
    ):
        load_trajectory_set(tmp_path / "release")


def test_a_byte_order_mark_before_the_first_line_is_dropped(tmp_path: Path) -> None:
    # An editor's BOM was refused as "not numbers: '\\ufeff0 1 ...'".
    (tmp_path / "obsmat.txt").write_text("\ufeff0 1 0 0 0 0 0 0\n6 1 0.5 0 0 0 0 0\n", encoding="utf-8")
    (tmp_path / "groups.txt").write_text("\ufeff1 2\n", encoding="utf-8")
    trajectories = load_trajectory_set(tmp_path)
    assert trajectories.people == 1 and len(trajectories.times) == 2


def test_replay_is_seeded_noisy_and_drops_detections_at_the_miss_rate(tmp_path: Path) -> None:
    trajectories = load_trajectory_set(write_set(tmp_path / "s", _walkers(frames=200)))
    settings = ReplaySettings(noise=0.1, miss_rate=0.2, seed=4)
    frames = list(replay(trajectories, settings))
    again = list(replay(trajectories, settings))
    assert [[(p.x, p.y) for p in f.detections] for f in frames] == [[(p.x, p.y) for p in f.detections] for f in again]
    seen = sum(len(f.detections) for f in frames)
    assert 0.75 < seen / (3 * 200) < 0.85
    errors = np.array(
        [[p.x - f.truth_positions[list(f.truth_ids).index(p.id)][0]] for f in frames for p in f.detections]
    )
    assert 0.08 < errors.std() < 0.12
    assert all(p.theta is None for f in frames for p in f.detections)  # the sets have no facing


def test_replay_at_a_camera_rate_interpolates_between_annotations(tmp_path: Path) -> None:
    trajectories = load_trajectory_set(write_set(tmp_path / "s", _walkers(frames=3)))
    frames = list(replay(trajectories, ReplaySettings(rate=5.0, noise=0.0, miss_rate=0.0)))
    assert [f.timestamp for f in frames] == pytest.approx([0.0, 0.2, 0.4, 0.6, 0.8])
    assert frames[1].truth_positions[0].tolist() == pytest.approx([0.2, 0.0])  # halfway between 0 and 0.4 m


def test_a_stray_annotation_between_steps_leaves_the_replay_at_a_camera_rate_whole(tmp_path: Path) -> None:
    """One extra row half a step after the others (frame 15 among 0, 10, 20, ...) took 0.2 s as the step between
    annotations: every 0.4 s step was then a gap, and the 5 Hz replay held nobody between annotations."""
    rows = [*_walkers(), (15, 1, 0.6, 0, 0.0, 1, 0, 0)]
    trajectories = load_trajectory_set(write_set(tmp_path / "s", rows))
    frames = list(replay(trajectories, ReplaySettings(rate=5.0, noise=0.0, miss_rate=0.0)))
    assert len(frames) == 9 and [f.truth_ids.tolist() for f in frames] == [[1, 2, 3]] * 9
    assert frames[1].truth_positions[2].tolist() == pytest.approx([4.8, 3.0])  # 3 between 5 m and 4.6 m


def test_people_annotated_on_different_frames_are_each_replayed_between_their_own_annotations(tmp_path: Path) -> None:
    """Person 3 annotated 5 frames after 1 and 2 (each every 10 frames): the step is 10 frames, 0.4 s, and every
    annotation time holds everyone annotated around it, not only those annotated on that frame."""
    rows = [row if row[1] != 3 else (row[0] + 5, 3, row[2] - 0.2, *row[3:]) for row in _walkers()]
    trajectories = load_trajectory_set(write_set(tmp_path / "s", rows, "1 2\n"))
    assert trajectories.notes == () and trajectories.times.tolist() == pytest.approx([0.2 * k for k in range(10)])
    frames = list(replay(trajectories, ReplaySettings(noise=0.0, miss_rate=0.0)))
    assert [f.truth_ids.tolist() for f in frames] == [[1, 2]] + [[1, 2, 3]] * 8 + [[3]]
    np.testing.assert_allclose(frames[1].truth_positions, [[0.2, 0.0], [0.2, 0.6], [4.8, 3.0]])
    at_rate = list(replay(trajectories, ReplaySettings(rate=5.0, noise=0.0, miss_rate=0.0)))
    assert [f.truth_ids.tolist() for f in at_rate] == [f.truth_ids.tolist() for f in frames]


def test_replay_in_a_field_of_view_keeps_only_the_people_inside(tmp_path: Path) -> None:
    trajectories = load_trajectory_set(write_set(tmp_path / "s", _walkers(frames=1)))
    view = ViewCone(-1.0, 0.3, 0.0, np.radians(40), max_range=3.0)  # looking along +x from behind the pair
    (frame,) = replay(trajectories, ReplaySettings(noise=0.0, miss_rate=0.0, view=view))
    assert frame.truth_ids.tolist() == [1, 2] and [p.id for p in frame.detections] == [1, 2]


def test_the_shared_sets_load_with_their_groups() -> None:
    for name, people in (("seq_eth", 360), ("seq_hotel", 390), ("zara01", 148)):
        trajectories = load_trajectory_set(shared_path("data", "trajectories", name))
        assert trajectories.people == people and len(trajectories.groups) > 30
        assert np.diff(trajectories.times).min() == pytest.approx(0.4)

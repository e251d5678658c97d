"""F-formation loading and scoring: a tiny dataset written here, the protocol's corner cases, the real sets."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import scipy.io

from sid.documents import InputWarning
from sid.experiments.fformation import (
    PLAUSIBLE_NEIGHBOUR_M,
    LabelledFrame,
    YawUnitError,
    cross_validate,
    evaluate,
    facing_agreement,
    fitting_unit,
    format_threshold,
    frame_precision_recall,
    gcff_settings,
    group_errors,
    load_dataset,
    load_dataset_any_yaw,
    load_dataset_in_metres,
    load_sequence,
    median_member_distance,
    median_neighbour_distance,
    missing_members,
    most_shared,
    parse_threshold,
    repeated_members,
    score,
    sequence_folders,
    shifted_ids,
    unit_warning,
    with_facing_noise,
    without_facings,
)
from sid.perception.groups import GroupParams, detect_groups
from tests.conftest import shared_path

REAL_SETS = ("Synth", "CoffeeBreak", "CocktailParty", "GDet")


def cells(items: list) -> np.ndarray:
    """A 1 x N MATLAB cell array."""
    array = np.empty((1, len(items)), dtype=object)
    for k, item in enumerate(items):
        array[0, k] = item
    return array


def write_sequence(folder: Path, frames: list[np.ndarray], truth: dict[int, list[list[int]]]) -> Path:
    """features.mat (frames stamped 1..N) and groundtruth.mat (groups per stamped frame) as the datasets store them."""
    folder.mkdir(parents=True, exist_ok=True)
    scipy.io.savemat(
        folder / "features.mat",
        {"features": cells(frames), "timestamp": np.arange(1, len(frames) + 1, dtype=np.uint8)[None, :]},
    )
    stamps = sorted(truth)
    groups = cells([cells([np.array([ids], dtype=np.uint8) for ids in truth[t]]) for t in stamps])
    scipy.io.savemat(folder / "groundtruth.mat", {"GTgroups": groups, "GTtimestamp": np.array([stamps], np.uint8)})
    return folder


def tiny_frames() -> list[np.ndarray]:
    """Three frames in centimetres: a face-to-face pair and a loner; a triangle facing its centre; two back to back."""
    pair = np.array([[1, 100.0, 0.0, 0.0], [2, 180.0, 0.0, math.pi], [3, 600.0, 300.0, 1.0]])
    triangle = np.array(
        [[k + 1, 70 * math.cos(a), 70 * math.sin(a), a + math.pi] for k, a in enumerate(np.radians([90, 210, 330]))]
    )
    back_to_back = np.array([[4, 0.0, 0.0, math.pi], [5, 60.0, 0.0, 0.0]])
    return [pair, triangle, back_to_back, pair]


@pytest.fixture
def tiny(tmp_path: Path) -> Path:
    # Frame 4 has features but no ground truth: it must not be scored.
    return write_sequence(tmp_path / "Tiny", tiny_frames(), {1: [[1, 2]], 2: [[1, 2, 3]], 3: [[4, 5]]})


def test_loads_only_frames_with_ground_truth_in_metres(tiny):
    frames = load_sequence(tiny, scale=0.01)
    assert [f.timestamp for f in frames] == [1.0, 2.0, 3.0]
    assert [sorted(map(sorted, f.truth)) for f in frames] == [[[1, 2]], [[1, 2, 3]], [[4, 5]]]
    first = frames[0].people
    assert [(p.id, p.x, p.y) for p in first] == [(1, 1.0, 0.0), (2, 1.8, 0.0), (3, 6.0, 3.0)]
    assert first[1].theta == pytest.approx(math.pi)


def test_scores_the_tiny_dataset_by_hand(tiny):
    # Frames 1 and 2 are found exactly (P = R = 1); frame 3 has truth but no detection (P = 1, R = 0).
    result = evaluate({"Tiny": load_dataset(tiny, 0.01)})
    for threshold in ("2/3", "1"):
        assert result["Tiny"][threshold] == pytest.approx({"precision": 1.0, "recall": 2 / 3, "f1": 0.8, "frames": 3})
    assert "pooled" not in result


def test_sequences_in_sub_folders_are_pooled_and_datasets_pooled_again(tmp_path):
    frames = tiny_frames()
    write_sequence(tmp_path / "Set" / "Seq1", frames, {1: [[1, 2]]})
    write_sequence(tmp_path / "Set" / "Seq2", frames, {3: [[4, 5]]})
    dataset = load_dataset(tmp_path / "Set", 0.01)
    assert [(f.sequence, f.timestamp) for f in dataset] == [("Seq1", 1.0), ("Seq2", 3.0)]
    other = write_sequence(tmp_path / "Other", frames, {2: [[1, 2, 3]]})
    result = evaluate({"Set": dataset, "Other": load_dataset(other, 0.01)}, thresholds=(2 / 3,))
    assert result["Set"]["2/3"]["recall"] == pytest.approx(0.5)
    assert result["Other"]["2/3"]["recall"] == pytest.approx(1.0)
    assert result["pooled"]["2/3"]["frames"] == 3 and result["pooled"]["2/3"]["recall"] == pytest.approx(2 / 3)


def test_a_frame_whose_truth_holds_no_group_is_scored_as_empty(tmp_path):
    folder = write_sequence(tmp_path / "Quiet", tiny_frames(), {3: []})
    [frame] = load_sequence(folder, 0.01)
    assert frame.truth == [] and len(frame.people) == 2
    assert evaluate({"Quiet": [frame]})["Quiet"]["2/3"]["f1"] == 1.0  # nothing found, nothing true


@pytest.mark.parametrize(
    ("detected", "truth", "threshold", "expected"),
    [
        ([], [], 2 / 3, (1.0, 1.0)),
        ([], [[1, 2]], 2 / 3, (1.0, 0.0)),
        ([[1, 2]], [], 2 / 3, (0.0, 1.0)),
        ([[1, 2, 3]], [[1, 2]], 2 / 3, (1.0, 1.0)),  # 2 of max(3, 2) members
        ([[1, 2, 3]], [[1, 2]], 1.0, (0.0, 0.0)),
        ([[1, 3]], [[1, 2]], 2 / 3, (0.0, 0.0)),  # pairs must match exactly
        ([[1, 2, 3, 4]], [[1, 2, 3]], 2 / 3, (1.0, 1.0)),  # 3 of 4
        ([[1, 2], [3, 4]], [[1, 2], [5, 6]], 2 / 3, (0.5, 0.5)),
        ([[7]], [[1, 2]], 2 / 3, (1.0, 0.0)),  # a detected singleton is dropped
    ],
)
def test_frame_precision_recall_follows_the_protocol(detected, truth, threshold, expected):
    assert frame_precision_recall(detected, truth, threshold) == pytest.approx(expected)


def test_score_averages_over_frames_then_takes_f1(tiny):
    frames = load_sequence(tiny, 0.01)
    result = score(frames, [[(1, 2)], [(1, 2)], [(4, 5)]], 2 / 3)
    # Frame 2 finds 2 of 3 (counts at 2/3); frame 3 finds the pair: P = R = 1.
    assert (result.precision, result.recall, result.f1, result.frames) == (1.0, 1.0, 1.0, 3)
    assert score(frames, [[(1, 2)], [(1, 2)], [(4, 5)]], 1.0).recall == pytest.approx(2 / 3)
    with pytest.raises(ValueError, match="2 detection lists for 3 frames"):
        score(frames, [[], []], 1.0)


def test_thresholds_parse_and_format():
    assert parse_threshold("2/3") == pytest.approx(2 / 3) and parse_threshold("1") == 1.0
    assert format_threshold(2 / 3) == "2/3" and format_threshold(1.0) == "1" and format_threshold(0.9) == "0.9"
    assert parse_threshold("0.51") == pytest.approx(0.51)
    for bad in ("0", "1/2", "1/3", "1.5", "x", "1/0"):
        with pytest.raises(ValueError, match="threshold"):
            parse_threshold(bad)


def test_a_tolerance_of_one_half_or_below_is_refused_rather_than_counting_a_detection_twice():
    # At T = 1/2 the one detected group [1, 2, 3, 4] would find both true pairs: two hits from one detection.
    for threshold in (0.5, 1 / 3):
        with pytest.raises(ValueError, match=r"threshold .* must lie in \(1/2, 1\]"):
            frame_precision_recall([[1, 2, 3, 4]], [[1, 2], [3, 4]], threshold)
    assert frame_precision_recall([[1, 2, 3, 4]], [[1, 2], [3, 4]], 2 / 3) == (0.0, 0.0)


def test_malformed_files_give_clear_errors(tmp_path, tiny):
    with pytest.raises(ValueError, match="not a folder"):
        load_dataset(tmp_path / "absent")
    empty = tmp_path / "Empty"
    empty.mkdir()
    with pytest.raises(ValueError, match="no features.mat"):
        load_dataset(empty)
    broken = tmp_path / "Broken"
    broken.mkdir()
    (broken / "features.mat").write_text("not a MATLAB file")
    (broken / "groundtruth.mat").write_bytes((tiny / "groundtruth.mat").read_bytes())
    with pytest.raises(ValueError, match="cannot read .*features.mat as a MATLAB file"):
        load_sequence(broken)
    scipy.io.savemat(broken / "features.mat", {"feat": np.zeros(3)})
    with pytest.raises(ValueError, match=r"lacks the variable\(s\) \['features', 'timestamp'\]"):
        load_sequence(broken)
    scipy.io.savemat(broken / "features.mat", {"features": cells([np.zeros((2, 3))]), "timestamp": np.array([[1]])})
    with pytest.raises(ValueError, match=r"N x 4 \[id, x, y, theta\]"):
        load_sequence(broken)
    scipy.io.savemat(broken / "features.mat", {"features": cells([np.zeros((0, 0))]), "timestamp": np.array([[9]])})
    with pytest.raises(ValueError, match="GTtimestamp 1.0 has no frame"):
        load_sequence(broken)
    with pytest.raises(ValueError, match="scale must be a positive number"):
        load_sequence(tiny, scale=0.0)


def test_variables_saved_as_the_fields_of_one_struct_are_read(tmp_path, tiny):
    """MATLAB's save(FILE, 'S') of a struct S holding features and timestamp: refused as lacking them."""
    wrapped = tmp_path / "Wrapped"
    wrapped.mkdir()
    for name in ("features", "groundtruth"):
        data = {k: v for k, v in scipy.io.loadmat(tiny / f"{name}.mat").items() if not k.startswith("__")}
        scipy.io.savemat(wrapped / f"{name}.mat", {"S": data, "note": "exported"})
    assert evaluate({"w": load_dataset(wrapped, 0.01)}) == evaluate({"w": load_dataset(tiny, 0.01)})
    two = {"features": 1, "timestamp": 1}  # two structs that could hold them: which one is meant?
    scipy.io.savemat(wrapped / "features.mat", {"A": two, "B": two})
    with pytest.raises(
        ValueError, match=r"lacks the variable\(s\) \['features', 'timestamp'\] \(it holds \['A', 'B'\]\)"
    ):
        load_sequence(wrapped)


def test_a_matlab_v73_file_is_named_with_how_to_save_it_readably(tmp_path, tiny):
    """scipy's answer was "Please use HDF reader for matlab v7.3 files, e.g. h5py", a library sid does not use."""
    folder = tmp_path / "HDF5"
    folder.mkdir()
    header = b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Mon Jan  1 00:00:00 2024 HDF5 schema 1.00 ."
    (folder / "features.mat").write_bytes(header.ljust(124, b" ") + b"\x00\x02IM" + b"\x89HDF\r\n\x1a\n" + bytes(600))
    (folder / "groundtruth.mat").write_bytes((tiny / "groundtruth.mat").read_bytes())
    with pytest.raises(ValueError, match=r"it is a MATLAB v7.3 \(HDF5\) file; save it again in MATLAB with save\(FILE"):
        load_sequence(folder)


def test_sequences_without_ground_truth_beside_labelled_ones_are_left_out_with_a_warning(tmp_path, tiny):
    """A release's unannotated test sequence stopped the whole dataset: "ZTest/groundtruth.mat is missing"."""
    dataset = tmp_path / "Release"
    write_sequence(dataset / "Seq1", tiny_frames(), {1: [[1, 2]], 2: [[1, 2, 3]], 3: [[4, 5]]})
    (dataset / "ZTest").mkdir()
    (dataset / "ZTest" / "features.mat").write_bytes((tiny / "features.mat").read_bytes())
    (dataset / "ZTest" / "GroundTruth.mat").write_bytes((tiny / "groundtruth.mat").read_bytes())
    with pytest.warns(InputWarning, match="Release: 1 sequence without groundtruth.mat not scored: ZTest"):
        frames = load_dataset(dataset, 0.01)
    assert len(frames) == 3 and {f.sequence for f in frames} == {"Seq1"}
    with pytest.raises(
        ValueError, match=r"ZTest/groundtruth.mat is missing \(the folder holds GroundTruth.mat, features.mat\)"
    ):
        load_dataset(dataset / "ZTest")


def _write_features(folder: Path, frames: list[np.ndarray], stamps: np.ndarray) -> None:
    scipy.io.savemat(folder / "features.mat", {"features": cells(frames), "timestamp": stamps[None, :]})


def test_ids_must_be_whole_and_unique_and_timestamps_unique(tmp_path):
    folder = write_sequence(tmp_path / "Ids", tiny_frames(), {1: [[1, 2]]})
    five = np.array([[k, 100.5 * k, 20.25, 0.1 * k] for k in range(1, 6)])
    _write_features(folder, [five.T.copy()], np.array([1.0]))  # 4 x 5: "people" (1, 2, ...), (100.5, 201, ...), ...
    with pytest.raises(ValueError, match=r"Ids/features.mat frame at timestamp 1: ids .* whole numbers, got 100.5"):
        load_sequence(folder)
    repeated = tiny_frames()[0].copy()
    repeated[2, 0] = 1
    _write_features(folder, [repeated], np.array([1.0]))
    with pytest.raises(ValueError, match="timestamp 1: person id 1 appears more than once"):
        load_sequence(folder)
    _write_features(folder, tiny_frames(), np.array([1.0, 2.0, 1.0, 2.0]))  # two takes numbered alike
    with pytest.raises(ValueError, match=r"features.mat: timestamp repeats 1, 2: each frame needs its own"):
        load_sequence(folder)
    groups = cells([cells([np.array([[1, 2]])]), cells([np.array([[1, 2]])])])
    scipy.io.savemat(folder / "groundtruth.mat", {"GTgroups": groups, "GTtimestamp": np.array([[1, 1]])})
    _write_features(folder, tiny_frames(), np.arange(1.0, 5.0))
    with pytest.raises(ValueError, match="groundtruth.mat: GTtimestamp repeats 1"):
        load_sequence(folder)
    scipy.io.savemat(folder / "groundtruth.mat", {"GTgroups": cells([np.array([[1.5, 2]])]), "GTtimestamp": [[1]]})
    with pytest.raises(ValueError, match="group member ids must be finite whole numbers"):
        load_sequence(folder)


def test_yaws_in_degrees_are_refused_as_radians_and_read_with_degrees(tmp_path):
    frames = tiny_frames()
    in_degrees = [np.column_stack([f[:, :3], np.degrees(f[:, 3])]) for f in frames]
    folder = write_sequence(tmp_path / "Degrees", in_degrees, {1: [[1, 2]], 2: [[1, 2, 3]], 3: [[4, 5]]})
    with pytest.raises(ValueError, match=r"theta reaches 180, beyond two turns: not radians.*degrees=True"):
        load_sequence(folder, 0.01)
    read = load_dataset(folder, 0.01, degrees=True)
    expected = load_dataset(
        write_sequence(tmp_path / "Radians", frames, {1: [[1, 2]], 2: [[1, 2, 3]], 3: [[4, 5]]}), 0.01
    )
    yaws = [p.theta for f in read for p in f.people]
    assert yaws == pytest.approx([p.theta for f in expected for p in f.people])
    # Unwrapped radians (the triangle's a + pi reaches 8.9 rad) are still radians.
    assert max(abs(p.theta) for f in expected for p in f.people if p.theta is not None) > 2 * math.pi
    # Left to the data, each dataset is read in the unit its yaws fit.
    assert load_dataset_any_yaw(folder, 0.01) == (read, True)
    assert load_dataset_any_yaw(tmp_path / "Radians", 0.01) == (expected, False)
    assert load_dataset_in_metres(folder)[0] == read and load_dataset_in_metres(folder)[1:] == (
        "centimetres",
        0.01,
        True,
    )
    with pytest.raises(YawUnitError):
        load_dataset_any_yaw(folder, 0.01, degrees=False)
    # Beyond two turns in degrees too: the message used to ask for degrees=True, which was given.
    spun = [np.column_stack([f[:, :3], f[:, 3] * 1e4]) for f in in_degrees]
    write_sequence(folder, spun, {1: [[1, 2]], 2: [[1, 2, 3]], 3: [[4, 5]]})
    for degrees in (True, None):
        with pytest.raises(ValueError, match=r"theta reaches 1.8e\+06 degrees, .*: neither radians nor degrees"):
            load_dataset_any_yaw(folder, 0.01, degrees=degrees)


def test_ground_truth_encodings_and_single_precision_timestamps(tmp_path):
    folder = tmp_path / "Encodings"
    folder.mkdir()
    four = np.array([[k, 100.0 * k, 0.0, 0.0] for k in range(1, 5)])
    _write_features(folder, [four, four], np.array([0.1, 0.2]))  # double precision
    truth = cells([np.array([[1, 2], [3, 4]]), cells([np.array([[1, 2, 3]])])])  # a matrix of rows; a cell of one
    stamps = np.array([[0.1, 0.2]], dtype=np.float32)  # single precision: 0.1 is 0.10000000149...
    scipy.io.savemat(folder / "groundtruth.mat", {"GTgroups": truth, "GTtimestamp": stamps})
    frames = load_sequence(folder, 0.01)
    assert [f.timestamp for f in frames] == [0.1, 0.2]
    assert [sorted(map(sorted, f.truth)) for f in frames] == [[[1, 2], [3, 4]], [[1, 2, 3]]]
    scipy.io.savemat(folder / "groundtruth.mat", {"GTgroups": cells([]), "GTtimestamp": np.zeros((1, 0))})
    with pytest.raises(ValueError, match="Encodings has no frame with ground truth"):
        load_dataset(folder)


def test_a_folder_of_datasets_is_refused_naming_them(tmp_path):
    """The shared fformation folder itself scored Synth and CocktailParty pooled as one dataset's sequences and
    left CoffeeBreak and GDet (sequences one level deeper) out, without a word."""
    truth = {1: [[1, 2]], 2: [[1, 2, 3]], 3: [[4, 5]]}
    for sequence in ("Single", "Several/Seq1", "Several/Seq2"):
        write_sequence(tmp_path / "all" / sequence, tiny_frames(), truth)
    with pytest.raises(
        ValueError, match=r"all holds datasets, not one \(Several, Single\): give each dataset's folder"
    ):
        load_dataset(tmp_path / "all")
    assert len(load_dataset(tmp_path / "all" / "Several")) == 6


def test_a_ground_truth_matrix_padded_with_zeros_or_nan_lists_the_shorter_groups(tmp_path):
    """[1 2 0; 3 4 5] (MATLAB's padding of a matrix of groups) made 0 a member of the pair, which then never matched;
    with NaN the file was refused. 0 is padding only where nobody of the frame has id 0."""
    folder = tmp_path / "Padded"
    folder.mkdir()
    five = np.array([[k, 100.0 * k, 0.0, 0.0] for k in range(1, 6)])
    _write_features(folder, [five, five - [1, 0, 0, 0]], np.array([1.0, 2.0]))  # ids 1-5, then 0-4
    truth = cells([np.array([[1, 2, 0], [3, 4, 5]]), np.array([[0, 1, np.nan], [2, 3, 4]])])
    scipy.io.savemat(folder / "groundtruth.mat", {"GTgroups": truth, "GTtimestamp": np.array([[1.0, 2.0]])})
    frames = load_sequence(folder, 0.01)
    assert [sorted(map(sorted, f.truth)) for f in frames] == [[[1, 2], [3, 4, 5]], [[0, 1], [2, 3, 4]]]
    scipy.io.savemat(folder / "features.mat", {"features": np.zeros((5, 4, 2)), "timestamp": np.array([[1.0, 2.0]])})
    with pytest.raises(ValueError, match="features must be a cell array, got float64"):
        load_sequence(folder)
    records = np.array([[(np.array([1.0]), np.array([0.0]))]], dtype=[("id", "O"), ("x", "O")])
    scipy.io.savemat(folder / "features.mat", {"features": records, "timestamp": np.array([[1.0]])})
    with pytest.raises(ValueError, match=r"features must be a cell array, got a struct array \(fields id, x\)"):
        load_sequence(folder)


def test_unit_warning_names_the_scale_that_fits(tiny):
    assert unit_warning(load_dataset(tiny, 0.01), 0.01) is None
    centimetres_as_metres = unit_warning(load_dataset(tiny, 1.0), 1.0)
    assert centimetres_as_metres is not None and "median distance" in centimetres_as_metres
    assert "look like centimetres, scale 0.01" in centimetres_as_metres
    # Millimetres scaled as centimetres (0.8 m gaps read as 8 m), and metres scaled as centimetres (0.008 m).
    assert "millimetres, scale 0.001" in str(unit_warning(load_dataset(tiny, 0.1), 0.01))
    assert "metres, scale 1" in str(unit_warning(load_dataset(tiny, 0.0001), 0.01))
    assert "check the file's units" in str(unit_warning(load_dataset(tiny, 1e-6), 1.0))
    assert unit_warning([], 1.0) is None
    stacked = [replace(f, people=[replace(p, x=0.0, y=0.0) for p in f.people]) for f in load_dataset(tiny, 0.01)]
    assert "is 0 m, implausible for people" in str(unit_warning(stacked, 0.01))  # no scale mends it


def test_people_without_a_finite_position_are_left_out_and_counted(tmp_path):
    lost = np.array([[1, 100.0, 0.0, 0.0], [2, np.nan, np.nan, math.pi], [3, 600.0, np.inf, 1.0]])
    frames = load_sequence(write_sequence(tmp_path / "Lost", [lost, tiny_frames()[0]], {1: [[1, 2]], 2: [[1, 2]]}))
    assert [[p.id for p in f.people] for f in frames] == [[1], [1, 2, 3]]
    assert [f.unplaced for f in frames] == [2, 0]
    assert missing_members(frames) == (1, 4)  # person 2's group membership is not scored in frame 1
    bad_id = np.array([[np.nan, 100.0, 0.0, 0.0]])
    with pytest.raises(ValueError, match="non-finite person id"):
        load_sequence(write_sequence(tmp_path / "BadId", [bad_id], {1: [[1, 2]]}))


def test_complex_numbers_and_scales_that_overflow_are_refused_naming_the_frame(tmp_path, recwarn):
    # numpy dropped the imaginary part with only a ComplexWarning: x = 100j was read as 0.
    imaginary = tiny_frames()[0].astype(complex)
    imaginary[1, 1] = 100j
    with pytest.raises(ValueError, match="Complex/features.mat frame at timestamp 1: features must be a real N x 4"):
        load_sequence(write_sequence(tmp_path / "Complex", [imaginary], {1: [[1, 2]]}))
    folder = write_sequence(tmp_path / "Tiny", tiny_frames(), {1: [[1, 2]]})
    scipy.io.savemat(folder / "groundtruth.mat", {"GTgroups": cells([np.array([[1, 2j]])]), "GTtimestamp": [[1]]})
    with pytest.raises(ValueError, match="groundtruth.mat at timestamp 1: a group must list real ids"):
        load_sequence(folder)
    # 100 cm x 1e308 is infinity: the group detector's "non-finite position" named no file, after a numpy warning.
    with pytest.raises(ValueError, match=r"timestamp 1: position \(100, 0\) scaled by 1e\+308 overflows to infinity"):
        load_sequence(write_sequence(tmp_path / "Far", tiny_frames(), {1: [[1, 2]]}), scale=1e308)
    assert not [w for w in recwarn if issubclass(w.category, (RuntimeWarning, np.exceptions.ComplexWarning))]


def test_missing_members_counts_truth_ids_absent_from_their_frame(tiny):
    frames = load_dataset(tiny, 0.01)
    assert missing_members(frames) == (0, 7)
    shifted = [replace(f, truth=[frozenset(i - 1 for i in g) for g in f.truth]) for f in frames]  # zero-based truth
    assert missing_members(shifted) == (3, 7)


# --- the real datasets (../shared/data/fformation) ---------------------------------------------------------------


def test_real_datasets_load_with_their_documented_sizes():
    synth = load_dataset(shared_path("data", "fformation", "Synth"), 0.01)
    coffee = load_dataset(shared_path("data", "fformation", "CoffeeBreak"), 0.01)
    assert len(synth) == 100 and len(coffee) == 45 + 74
    assert all(len(g) > 1 for f in synth + coffee for g in f.truth)
    people = [p for f in coffee for p in f.people]
    assert all(-3.0 < p.x < 3.5 and -3.5 < p.y < 5.5 and p.theta is not None for p in people), "metres"


def test_real_scores_with_the_default_parameters():
    # Measured with the defaults (the o-space method, docs/groups.md): F1 at T = 2/3 Synth 0.962, CoffeeBreak 0.787,
    # CocktailParty 0.857, GDet 0.789. GCFF with one setting for all sets (0.45 m, 3 m^2) scores 0.632 / 0.766 /
    # 0.869 / 0.769. These floors catch regressions of the detector or of the protocol.
    datasets = {name: load_dataset(shared_path("data", "fformation", name), 0.01) for name in REAL_SETS}
    result = evaluate(datasets)
    floors = {"Synth": (0.95, 0.6), "CoffeeBreak": (0.77, 0.54), "CocktailParty": (0.84, 0.62), "GDet": (0.77, 0.54)}
    for name, (loose, exact) in floors.items():
        assert result[name]["2/3"]["f1"] > loose and result[name]["1"]["f1"] > exact, name
        assert result[name]["1"]["f1"] < result[name]["2/3"]["f1"]
    assert result["pooled"]["2/3"]["frames"] == 942


def test_groups_from_positions_alone_on_the_real_sets_without_facings():
    # Every facing removed (a detector of positions only): the default finds almost nothing, as a group needs a
    # facing; positions-only groups (docs/groups.md, "Positions only") score F1 at T = 2/3 0.754 / 0.778 / 0.796 /
    # 0.725, and left one set out 0.675 / 0.778 / 0.796 / 0.725.
    datasets = {
        name: without_facings(load_dataset(shared_path("data", "fformation", name), 0.01), 1.0) for name in REAL_SETS
    }
    default, positions = evaluate(datasets), evaluate(datasets, GroupParams(positions_only_reach=1.0))
    expected = {"Synth": 0.754, "CoffeeBreak": 0.778, "CocktailParty": 0.796, "GDet": 0.725}
    for name, f1 in expected.items():
        assert default[name]["2/3"]["f1"] < 0.25 and positions[name]["2/3"]["f1"] == pytest.approx(f1, abs=5e-4), name


def test_facing_noise_is_seeded_and_leaves_unknown_facings_unknown(tiny):
    frames = load_sequence(tiny, 0.01)
    frames[0].people[0].theta = None
    noisy = with_facing_noise(frames, math.radians(20), seed=3)
    again = with_facing_noise(frames, math.radians(20), seed=3)
    assert [[p.theta for p in f.people] for f in noisy] == [[p.theta for p in f.people] for f in again]
    pairs = [(a, b) for f, g in zip(frames, noisy, strict=True) for a, b in zip(f.people, g.people, strict=True)]
    assert all((a.theta is None) == (b.theta is None) for a, b in pairs)
    assert any(a.theta is not None and a.theta != b.theta for a, b in pairs)
    assert [(a.id, a.x, a.y) for a, _ in pairs] == [(b.id, b.x, b.y) for _, b in pairs]
    with pytest.raises(ValueError, match="facing noise"):
        with_facing_noise(frames, -1.0)


def test_missing_facings_are_seeded_and_touch_nothing_else(tiny):
    frames = load_sequence(tiny, 0.01)
    thinned, again = without_facings(frames, 0.5, seed=3), without_facings(frames, 0.5, seed=3)
    assert [[p.theta for p in f.people] for f in thinned] == [[p.theta for p in f.people] for f in again]
    pairs = [(a, b) for f, g in zip(frames, thinned, strict=True) for a, b in zip(f.people, g.people, strict=True)]
    assert all(b.theta is None or b.theta == a.theta for a, b in pairs)
    assert any(b.theta is None for _, b in pairs) and any(b.theta is not None for _, b in pairs)
    assert [(a.id, a.x, a.y) for a, _ in pairs] == [(b.id, b.x, b.y) for _, b in pairs]
    assert all(p.theta is None for f in without_facings(frames, 1.0) for p in f.people)
    assert without_facings(frames, 0.0) == frames
    with pytest.raises(ValueError, match="share of facings missing"):
        without_facings(frames, 1.5)


def test_one_candidate_per_cluster_is_the_papers_algorithm_and_fails_in_crowds():
    synth = load_dataset(shared_path("data", "fformation", "Synth"), 0.01)
    paper = GroupParams(method="paper")
    rays = GroupParams(method="rays")
    assert GroupParams(method="rays", meeting_radius=math.inf) != paper  # another record, the same detector:
    assert [g.members for g in detect_groups(synth[0].people, replace(rays, meeting_radius=math.inf))] == [
        g.members for g in detect_groups(synth[0].people, paper)
    ]
    default_found = sum(len(detect_groups(f.people, rays)) for f in synth)
    paper_found = sum(len(detect_groups(f.people, paper)) for f in synth)
    assert paper_found < default_found


def test_cross_validation_leaves_each_dataset_out_once(tmp_path):
    frames = tiny_frames()
    datasets = {
        name: load_dataset(write_sequence(tmp_path / name, frames, {1: [[1, 2]], 2: [[1, 2, 3]]}), 0.01)
        for name in ("A", "B", "C")
    }
    # An alone price of 0.01 m^2 lets nobody join (F1 0); 0.65 finds both groups (F1 1) in every set.
    folds, table = cross_validate(datasets, {"alone_price": [0.01, 0.65], "radius_max": [0.8]})
    assert [f.held_out for f in folds] == ["A", "B", "C"]
    assert all(f.chosen == {"alone_price": 0.65, "radius_max": 0.8} for f in folds)
    assert all(f.held_out_f1 == 1.0 and f.train_f1 == 1.0 for f in folds)
    assert table[(0.01, 0.8)] == {"A": 0.0, "B": 0.0, "C": 0.0}
    with pytest.raises(ValueError, match="numeric fields of GroupParams"):
        cross_validate(datasets, {"stride": [0.5]})
    with pytest.raises(ValueError, match="at least two datasets"):
        cross_validate({"A": datasets["A"]}, {"group_price": [0.65]})


def test_cross_validation_in_worker_processes_gives_the_same_table(tmp_path):
    frames = tiny_frames()
    datasets = {
        name: load_dataset(write_sequence(tmp_path / name, frames, {1: [[1, 2]], 2: [[1, 2, 3]]}), 0.01)
        for name in ("A", "B")
    }
    grid = {"alone_price": [0.01, 0.3, 0.65], "group_price": [0.5, 0.8]}
    calls: list[tuple[int, int, str]] = []
    folds, table = cross_validate(datasets, grid)
    pooled = cross_validate(datasets, grid, workers=2, progress=lambda *call: calls.append(call))
    assert pooled == (folds, table) and list(pooled[1]) == list(table)  # the same points, in grid order
    assert sorted(done for done, _, _ in calls) == list(range(1, 7))
    assert {(total, what) for _, total, what in calls} == {(6, "grid points")}


def test_median_neighbour_distance_is_in_the_input_units(tiny):
    centimetres = median_neighbour_distance(load_dataset(tiny, 1.0))
    metres = median_neighbour_distance(load_dataset(tiny, 0.01))
    assert centimetres is not None and metres is not None
    assert centimetres == pytest.approx(100 * metres)
    assert centimetres > PLAUSIBLE_NEIGHBOUR_M[1] > metres > PLAUSIBLE_NEIGHBOUR_M[0]
    assert median_neighbour_distance([]) is None


def test_files_that_disagree_are_named_with_the_fformation_prefix(tmp_path):
    # Found by tests/fuzz/test_input_kinds.py: these three messages lacked the prefix every other one has.
    folder = write_sequence(tmp_path / "Odd", tiny_frames(), {1: [[1, 2]]})
    scipy.io.savemat(folder / "features.mat", {"features": cells(tiny_frames()), "timestamp": np.array([[1.0, 2.0]])})
    with pytest.raises(ValueError, match=r"^fformation: .*features.mat: 4 feature frames but 2 timestamps$"):
        load_sequence(folder)
    write_sequence(folder, tiny_frames(), {9: [[1, 2]]})
    with pytest.raises(
        ValueError, match=r"^fformation: .*groundtruth.mat: GTtimestamp 9.0 has no frame in features.mat$"
    ):
        load_sequence(folder)
    write_sequence(folder, tiny_frames(), {9: [[1, 2]], 10: [[1, 2]]})
    with pytest.raises(ValueError, match=r"GTtimestamp 9.0 has no frame in features.mat \(nor do the other 1\)$"):
        load_sequence(folder)


def test_ground_truth_frames_without_features_are_not_scored_with_a_warning(tmp_path):
    folder = write_sequence(tmp_path / "Slip", tiny_frames(), {1: [[1, 2]], 9: [[4, 5]], 2: [[1, 2, 3]]})
    with pytest.warns(InputWarning, match=r"groundtruth.mat: 1 ground-truth frame of 3 without a frame in features"):
        frames = load_sequence(folder)
    assert [f.timestamp for f in frames] == [1.0, 2.0]


def test_stamps_beyond_single_precision_load_without_a_numpy_warning(tmp_path, recwarn):
    # Found by tests/fuzz/test_input_kinds.py: casting 1e300 to single precision printed an overflow RuntimeWarning.
    folder = write_sequence(tmp_path / "Far", tiny_frames()[:2], {1: [[1, 2]]})
    stamps = np.array([[1.0, 1e300]])
    scipy.io.savemat(folder / "features.mat", {"features": cells(tiny_frames()[:2]), "timestamp": stamps})
    scipy.io.savemat(
        folder / "groundtruth.mat", {"GTgroups": cells([cells([np.array([[1.0, 2.0]])])] * 2), "GTtimestamp": stamps}
    )
    assert [f.timestamp for f in load_sequence(folder, scale=0.01)] == [1.0, 1e300]
    assert not [w for w in recwarn if issubclass(w.category, RuntimeWarning)]


def test_group_errors_name_how_each_true_group_came_out():
    """One frame per kind; the detected group sharing most members is the one judged (ties: fewest others)."""
    truth = [frozenset({1, 2, 3})]
    frame = LabelledFrame("s", 0.0, [], truth)
    cases = {
        "exact": [[1, 2, 3]],
        "one_too_many": [[1, 2, 3, 4]],
        "more_too_many": [[1, 2, 3, 4, 5]],
        "lacking": [[1, 2], [3, 9]],  # the pair shares two, the other one
        "mixed": [[1, 2, 7]],
        "missed": [[1, 8], [2, 9]],  # no group holds two of them: and each is a false group
    }
    for kind, found in cases.items():
        counts = group_errors([frame], [found])
        assert counts[kind] == 1 and sum(counts[k] for k in cases) == 1, kind
    assert group_errors([frame], [[[1, 8], [2, 9]]])["false_groups"] == 2
    assert group_errors([frame], [[[1, 2, 3, 4], [1, 2, 3]]])["exact"] == 1  # a tie on shared members: fewest others
    with pytest.raises(ValueError, match="2 detection lists for 1 frames"):
        group_errors([frame], [[], []])


def test_features_with_more_than_four_columns_are_read_from_the_first_four_with_a_warning(tmp_path: Path) -> None:
    """A set with a second facing per person (head and body, as some annotations hold) reads [id, x, y, theta] and
    says the other columns are not used, instead of dropping them without a word."""
    plain = load_sequence(write_sequence(tmp_path / "Four", tiny_frames(), {1: [[1, 2]], 2: [[1, 2, 3]]}))
    wide = [np.column_stack((frame, frame[:, 3] + 0.5)) for frame in tiny_frames()]  # a body facing beside the head's
    with pytest.warns(InputWarning, match=r"features have 5 columns: \[id, x, y, theta\] are read from the first four"):
        frames = load_sequence(write_sequence(tmp_path / "Five", wide, {1: [[1, 2]], 2: [[1, 2, 3]]}))
    assert [[(p.id, p.x, p.y, p.theta) for p in f.people] for f in frames] == [
        [(p.id, p.x, p.y, p.theta) for p in f.people] for f in plain
    ]


def test_the_detected_group_sharing_most_members_fewest_strangers_on_ties_is_chosen():
    true = frozenset({1, 2, 3})
    assert most_shared([frozenset({1, 2, 9}), frozenset({1, 2}), frozenset({3})], true) == 1
    assert most_shared([frozenset({1, 5}), frozenset({2, 6})], frozenset({1, 2})) == 0  # the first of equals
    assert most_shared([frozenset({7, 8})], true) == 0 and most_shared([], true) is None


def _circles(groups: list[int], loners: int, unit: float) -> tuple[np.ndarray, list[list[int]]]:
    """One frame: groups of the given sizes on 0.7 m circles facing their centres, 6 m apart, and people standing
    alone 4 m from anyone, in units of ``unit`` metres (0.01: centimetres); the rows and the true groups."""
    rows, truth, k = [], [], 1
    for g, size in enumerate(groups):
        members = []
        for j in range(size):
            a = 2 * math.pi * j / size
            rows.append([k, (6.0 * g + 0.7 * math.cos(a)) / unit, 0.7 * math.sin(a) / unit, a + math.pi])
            members, k = [*members, k], k + 1
        truth.append(members)
    for j in range(loners):
        rows.append([k, 4.0 * j / unit, 20.0 / unit, 0.0])
        k += 1
    return np.array(rows), truth


def test_the_unit_comes_from_the_annotated_groups_spacing_when_most_people_stand_alone(tmp_path):
    # Everyone's median gap (4 m between the loners) fits centimetres and millimetres alike; the members' (1.4 m,
    # 1.21 m in a triangle) fits centimetres only. Read as millimetres every group was lost (F1 0).
    rows, truth = _circles([2, 2, 3], 9, 0.01)
    frames = load_sequence(write_sequence(tmp_path / "Sparse", [rows], {1: truth}))
    assert fitting_unit(frames) == ("centimetres", 0.01)
    assert median_member_distance(frames) == pytest.approx(140.0)  # the pairs, 1.4 m apart, and the trio, 1.21 m


def test_a_unit_that_puts_group_members_implausibly_close_is_named(tmp_path):
    # A top view at 20 pixels per metre read as centimetres: everyone's gaps look like people's, the members' do not.
    rows, truth = _circles([2, 3], 2, 0.05)
    frames = load_sequence(write_sequence(tmp_path / "Pixels", [rows], {1: truth}), scale=0.01)
    assert "ground-truth group member to the nearest fellow member is 0.242 m, implausible" in str(
        unit_warning(frames, 0.01)
    )


def test_ground_truth_ids_shifted_by_one_and_members_in_two_groups_are_found(tmp_path):
    rows, truth = _circles([2, 3], 0, 0.01)
    rows[:, 0] -= 1  # features count from 0, the ground truth from 1
    frames = load_sequence(write_sequence(tmp_path / "Shifted", [rows], {1: truth}), scale=0.01)
    assert shifted_ids(frames) == -1 and repeated_members(frames) == (0, 0)
    twice = [replace(frames[0], truth=[frozenset({0, 1}), frozenset({1, 2, 3})])]
    assert shifted_ids(twice) is None and repeated_members(twice) == (1, 1)


def test_a_matrix_of_groups_padded_with_0_whose_ids_start_at_0_keeps_person_0_in_one_group(tmp_path):
    # [0 2 9; 3 8 0]: 0 is in two rows, and nobody stands in two groups, so the 0 that ends a row is padding.
    rows = np.array([[i, 100.0 * i, 0.0, 0.0] for i in range(10)])
    folder = tmp_path / "Padded"
    folder.mkdir()
    scipy.io.savemat(folder / "features.mat", {"features": cells([rows]), "timestamp": np.array([[1]])})
    groups = cells([np.array([[0, 2, 9], [3, 8, 0]], dtype=float)])
    scipy.io.savemat(folder / "groundtruth.mat", {"GTgroups": groups, "GTtimestamp": np.array([[1]])})
    (frame,) = load_sequence(folder)
    assert sorted(map(sorted, frame.truth)) == [[0, 2, 9], [3, 8]]


def test_ground_truth_timestamps_written_with_fewer_digits_find_their_frames_and_other_clocks_do_not(tmp_path):
    # Frames at k / 15 s, the ground truth at round(k / 15, 3) as a text export writes it: 13 of 20 were dropped.
    frame = tiny_frames()[0]
    stamps = np.arange(20) / 15
    folder = tmp_path / "Rounded"
    folder.mkdir()
    scipy.io.savemat(folder / "features.mat", {"features": cells([frame] * 20), "timestamp": stamps[None, :]})
    truth = cells([cells([np.array([[1, 2]], dtype=np.uint8)])] * 20)
    scipy.io.savemat(folder / "groundtruth.mat", {"GTgroups": truth, "GTtimestamp": np.round(stamps, 3)[None, :]})
    assert [f.timestamp for f in load_sequence(folder)] == pytest.approx(stamps.tolist())
    # Another clock: one stamp half a frame away means none is taken near (a near match would be chance).
    shifted = np.round(stamps, 3)
    shifted[5] += 1 / 30
    scipy.io.savemat(folder / "groundtruth.mat", {"GTgroups": truth, "GTtimestamp": shifted[None, :]})
    with pytest.warns(InputWarning, match="13 ground-truth frames of 20 without a frame"):
        assert len(load_sequence(folder)) == 7


def test_features_stored_four_by_n_are_read_transposed_with_a_warning(tmp_path: Path) -> None:
    """Whole-number cm and degrees pass the id check the other way round: the shape tells (four rows in every frame,
    a column count that varies as people come and go)."""
    upright = write_sequence(tmp_path / "Upright", tiny_frames(), {1: [[1, 2]], 2: [[1, 2, 3]], 3: [[4, 5]]})
    turned = write_sequence(
        tmp_path / "Turned", [f.T for f in tiny_frames()], {1: [[1, 2]], 2: [[1, 2, 3]], 3: [[4, 5]]}
    )
    with pytest.warns(InputWarning, match="every frame's features have 4 rows, read as 4 x N"):
        frames = load_sequence(turned, 0.01)
    assert frames == [replace(f, sequence="Turned") for f in load_sequence(upright, 0.01)]
    # The same six people in every frame: the ids recur along the first row, positions down the first column.
    six = [np.array([[k, 100.0 * k + t, 50.0 * t, 0.1 * k] for k in range(1, 7)]) for t in range(3)]
    truth = {1: [[1, 2]], 2: [[3, 4]], 3: [[5, 6]]}
    constant = write_sequence(tmp_path / "Six", [f.T for f in six], truth)
    with pytest.warns(InputWarning, match="read as 4 x N"):
        assert [[p.id for p in f.people] for f in load_sequence(constant)] == [[1, 2, 3, 4, 5, 6]] * 3
    # Four people with six columns each, in every frame: read as they are, without a word.
    wide = [np.column_stack([f[:4], np.zeros((4, 2))]) for f in six]
    with pytest.warns(InputWarning, match="features have 6 columns"):  # the extra columns' warning alone
        assert [[p.id for p in f.people] for f in load_sequence(write_sequence(tmp_path / "Wide", wide, truth))] == [
            [1, 2, 3, 4]
        ] * 3


def test_ground_truth_groups_as_cells_of_single_ids_keep_their_members(tmp_path: Path) -> None:
    folder = write_sequence(tmp_path / "Cells", tiny_frames(), {1: [[1, 2]]})
    frame_cell = cells([cells([np.array([[1]]), np.array([[2]])])])  # GTgroups{1} = {{1, 2}}
    scipy.io.savemat(folder / "groundtruth.mat", {"GTgroups": cells([frame_cell]), "GTtimestamp": [[1]]})
    assert [sorted(map(sorted, f.truth)) for f in load_sequence(folder)] == [[[1, 2]]]


def test_one_yaw_beyond_two_turns_among_radians_is_named_not_taken_for_degrees(tmp_path: Path) -> None:
    frames = [tiny_frames()[0].copy() for _ in range(10)]  # a pair and a loner, ten times: 30 yaws
    frames[0][0, 3] = 12.7  # one unwrapped yaw; every other within a turn
    folder = write_sequence(tmp_path / "Outlier", frames, {k: [[1, 2]] for k in range(1, 11)})
    with pytest.raises(ValueError, match=r"theta reaches 12.7, beyond two turns, while 3.3% .*neither radians nor"):
        load_dataset_any_yaw(folder, 0.01)


def test_ground_truth_stamps_rounded_to_a_fifth_of_a_frame_gap_find_their_frames(tmp_path: Path) -> None:
    folder = tmp_path / "Rounded"
    folder.mkdir()
    four = np.array([[k, 100.0 * k, 0.0, 0.0] for k in range(1, 5)])
    _write_features(folder, [four] * 3, np.array([1, 2, 3]) / 15)  # 15 fps
    truth = cells([np.array([[1, 2]])] * 3)
    scipy.io.savemat(folder / "groundtruth.mat", {"GTgroups": truth, "GTtimestamp": np.round(np.arange(1, 4) / 15, 2)})
    assert len(load_sequence(folder)) == 3  # 10 ms off of 67 ms gaps


def test_a_dataset_folder_with_its_own_file_and_sequence_folders_says_which_is_scored(tmp_path: Path) -> None:
    top = write_sequence(tmp_path / "Both", tiny_frames(), {1: [[1, 2]]})
    write_sequence(top / "Seq1", tiny_frames(), {1: [[1, 2]]})
    with pytest.warns(InputWarning, match="its own file is scored, Seq1 not"):
        assert sequence_folders(top) == [top]


def test_hidden_folders_are_no_sequences_and_gcff_settings_in_other_units_are_named(tmp_path: Path) -> None:
    dataset = tmp_path / "Set"
    for name in ("Seq1", ".Seq1_backup", "__MACOSX"):
        folder = write_sequence(dataset / name, tiny_frames(), {1: [[1, 2]]})
        scipy.io.savemat(folder / "settings_gc.mat", {"stride": [[3000.0]], "mdl": [[30000.0]]})  # in mm, say
    assert sequence_folders(dataset) == [dataset / "Seq1"]
    with pytest.warns(InputWarning, match=r"stride scaled by 0.01 is 30 m, implausible for people"):
        gcff_settings(dataset, scale=0.01)


def test_facing_agreement_is_the_mean_cosine_of_members_facings_towards_their_centre(tiny):
    frames = load_sequence(tiny, 0.01)
    # the pair face each other and the triangle its centre (+1 each), the two back to back away (-1 each)
    assert facing_agreement(frames) == pytest.approx(3 / 7)
    turned = [replace(f, people=[replace(p, theta=p.theta + math.pi) for p in f.people]) for f in frames]
    assert facing_agreement(turned) == pytest.approx(-3 / 7)
    assert facing_agreement([replace(f, truth=[]) for f in frames]) is None

"""The gated assignment against SciPy's solver, its fast path, and the walking groups' connected components."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from scipy.optimize import linear_sum_assignment
from scipy.sparse import csgraph, csr_matrix

from sid.tracking.assignment import gated_assignment
from sid.tracking.groups import connected_components


def _reference(cost: np.ndarray, allowed: np.ndarray) -> tuple[int, float]:
    """(allowed pairs, their total cost) of SciPy's assignment with pairs outside the gate (or not finite) priced
    out."""
    allowed = allowed & np.isfinite(cost)
    if not allowed.any():
        return 0, 0.0
    rows, cols = linear_sum_assignment(np.where(allowed, cost, 1e9))  # the costs are below 3
    kept = allowed[rows, cols]
    return int(kept.sum()), float(cost[rows[kept], cols[kept]].sum())


@pytest.mark.parametrize("seed", range(400))
def test_matches_as_many_pairs_as_scipy_at_the_same_least_cost(seed: int) -> None:
    rng = np.random.default_rng(seed)
    shape = tuple(rng.integers(1, 7, size=2))
    cost = rng.random(shape) * 3
    if seed % 4 == 0:  # ties: costs on a coarse grid
        cost = np.round(cost)
    allowed = rng.random(shape) < rng.uniform(0.2, 1.0)
    if seed % 5 == 1:  # a few non-finite costs
        cost[rng.random(shape) < 0.2] = rng.choice([np.nan, np.inf, -np.inf])
    rows, cols = gated_assignment(cost, allowed)
    assert (allowed & np.isfinite(cost))[rows, cols].all()
    assert len(set(rows.tolist())) == len(rows) and len(set(cols.tolist())) == len(cols)
    assert np.all(np.diff(rows) > 0)
    pairs, total = _reference(cost, allowed)
    assert len(rows) == pairs
    assert float(cost[rows, cols].sum()) == pytest.approx(total, abs=1e-9)


def test_a_pair_outside_the_gate_does_not_displace_one_inside() -> None:
    # Jaccard overlaps of two group tracks (rows) with two candidates, matched at >= 0.5: maximising the total over
    # every pair would match A-Y and B-X (0.9), both below the threshold; the gate keeps A-X.
    overlap = np.array([[0.6, 0.45], [0.45, 0.0]])
    rows, cols = gated_assignment(-overlap, overlap >= 0.5)
    assert rows.tolist() == [0] and cols.tolist() == [0]


def test_empty_and_fully_gated_matrices() -> None:
    for shape in ((0, 0), (0, 3), (3, 0), (2, 2)):
        rows, cols = gated_assignment(np.ones(shape), np.zeros(shape, dtype=bool))
        assert rows.size == cols.size == 0


def test_non_finite_costs_are_never_matched() -> None:
    cost = np.array([[np.nan, 1.0], [np.inf, 2.0]])
    rows, cols = gated_assignment(cost, np.ones((2, 2), dtype=bool))
    assert rows.tolist() == [0] and cols.tolist() == [1]  # one column left: the cheaper row takes it


@pytest.mark.parametrize("value", [np.nan, np.inf, -np.inf])
def test_a_gate_of_non_finite_costs_matches_nothing(value: float) -> None:
    for shape in ((1, 1), (2, 3)):
        rows, cols = gated_assignment(np.full(shape, value), np.ones(shape, dtype=bool))
        assert rows.size == cols.size == 0


def test_mismatched_shapes_are_an_error() -> None:
    with pytest.raises(ValueError, match="one shape"):
        gated_assignment(np.ones((2, 3)), np.ones((3, 2), dtype=bool))


def _solver_loaded_before_and_after(setup: str, step: str) -> list[str]:
    """Whether scipy.optimize is imported after ``setup`` and after ``step`` (Python lines), in a fresh process."""
    probe = "\n".join(
        ("import sys", setup, "print('scipy.optimize' in sys.modules)", step, "print('scipy.optimize' in sys.modules)")
    )
    return subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True).stdout.split()


def test_an_unambiguous_frame_does_not_import_the_solver() -> None:
    """The fast path answers without SciPy; a tie needs the solver, imported then."""
    setup = (
        "import numpy as np\n"
        "from sid.tracking.assignment import gated_assignment\n"
        "gated_assignment(np.array([[0.1, 2.0], [3.0, 0.2]]), np.ones((2, 2), dtype=bool))"
    )
    tie = "gated_assignment(np.array([[0.1, 0.1], [0.1, 0.1]]), np.ones((2, 2), dtype=bool))"
    assert _solver_loaded_before_and_after(setup, tie) == ["False", "True"]


@pytest.mark.parametrize("seed", range(100))
def test_components_equal_scipy(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 15))
    upper = np.triu(rng.random((n, n)) < rng.uniform(0.05, 0.5), 1)
    adjacent = upper | upper.T
    count, labels = csgraph.connected_components(csr_matrix(adjacent), directed=False)
    expected = [np.flatnonzero(labels == label).tolist() for label in range(count)]
    assert [rows.tolist() for rows in connected_components(adjacent)] == expected


def test_a_social_stream_loads_the_solver_up_front() -> None:
    """A robot's stream must not pause for the import on its first ambiguous frame."""
    setup = (
        "from costmap.grid import GridSpec\n"
        "from sid.perception.pipeline import Pipeline\n"
        "from sid.stream import SocialStream\n"
        "from sid.synthetic.pose import TruthPose"
    )
    build = "SocialStream(Pipeline(TruthPose()), GridSpec.from_size(0.05, (0.0, -5.0), (10.0, 10.0)))"
    assert _solver_loaded_before_and_after(setup, build) == ["False", "True"]

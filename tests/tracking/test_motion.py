"""The vectorised constant-velocity Kalman filter against the textbook matrix form, and its consistency (NEES)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from sid.tracking.motion import MotionStates


def _full_covariance(c: np.ndarray) -> np.ndarray:
    """(N, 2, 2) per-axis covariances from the filter's (N, 3) (pp, pv, vv) form."""
    return np.stack([np.stack([c[:, 0], c[:, 1]], -1), np.stack([c[:, 1], c[:, 2]], -1)], -2)


def _random_states(rng: np.random.Generator, n: int) -> MotionStates:
    a = rng.normal(size=(n, 2, 2))
    p = a @ a.transpose(0, 2, 1) + 0.05 * np.eye(2)  # symmetric positive definite
    return MotionStates(
        position=rng.normal(size=(n, 2)),
        velocity=rng.normal(size=(n, 2)),
        covariance=np.stack([p[:, 0, 0], p[:, 0, 1], p[:, 1, 1]], -1),
    )


@pytest.mark.parametrize("seed", range(5))
def test_predict_is_the_textbook_prediction(seed: int) -> None:
    rng = np.random.default_rng(seed)
    states = _random_states(rng, 7)
    dt, q = rng.uniform(0.01, 1.0), rng.uniform(0.01, 3.0)
    f = np.array([[1.0, dt], [0.0, 1.0]])
    noise = q * np.array([[dt**3 / 3, dt**2 / 2], [dt**2 / 2, dt]])
    expected_p = f @ _full_covariance(states.covariance) @ f.T + noise
    expected_position = states.position + dt * states.velocity
    states.predict(dt, q)
    np.testing.assert_allclose(_full_covariance(states.covariance), expected_p, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(states.position, expected_position, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("every", [True, False])
def test_correct_is_the_textbook_update(every: bool) -> None:
    rng = np.random.default_rng(3)
    states = _random_states(rng, 6)
    rows = np.arange(6) if every else np.array([1, 2, 4])
    measured = rng.normal(size=(len(rows), 2))
    r = 0.04
    h = np.array([[1.0, 0.0]])
    p = _full_covariance(states.covariance)
    x = np.stack([states.position, states.velocity], 1)  # (N, 2 [p, v], 2 axes)
    expected_p, expected_x = p.copy(), x.copy()
    for k, row in enumerate(rows):
        gain = p[row] @ h.T / (h @ p[row] @ h.T + r)  # (2, 1)
        expected_p[row] = (np.eye(2) - gain @ h) @ p[row]
        expected_x[row] = x[row] + gain @ (measured[k] - x[row, 0])[None, :]
    states.correct(rows, measured, r)
    np.testing.assert_allclose(_full_covariance(states.covariance), expected_p, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(states.position, expected_x[:, 0], rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(states.velocity, expected_x[:, 1], rtol=1e-12, atol=1e-12)


def test_the_filter_is_consistent_on_its_own_motion_model() -> None:
    """Average normalised estimation error squared over 200 simulated tracks stays inside its 99 % chi-square band."""
    rng = np.random.default_rng(11)
    n, steps, dt, q, r = 200, 60, 0.1, 0.5, 0.01
    true_p, true_v = np.zeros((n, 2)), rng.normal(0.0, 1.0, (n, 2))
    f = np.array([[1.0, dt], [0.0, 1.0]])
    chol = np.linalg.cholesky(q * np.array([[dt**3 / 3, dt**2 / 2], [dt**2 / 2, dt]]))
    states = MotionStates()
    states.append(true_p + rng.normal(0.0, np.sqrt(r), (n, 2)), r, 1.0)
    states.velocity[:] = 0.0
    nees = []
    for step in range(steps):
        x = np.stack([true_p, true_v], 1)  # (N, 2 [p, v], 2 axes)
        x = f @ x + chol @ rng.normal(size=(n, 2, 2))
        true_p, true_v = x[:, 0], x[:, 1]
        states.predict(dt, q)
        states.correct(np.arange(n), true_p + rng.normal(0.0, np.sqrt(r), (n, 2)), r)
        if step >= 20:  # past the start-up, where the velocity prior (variance 1 for N(0, 1) speeds) is honest too
            error = np.stack([states.position - true_p, states.velocity - true_v], 1)  # (N, 2, 2 axes)
            p_inv = np.linalg.inv(_full_covariance(states.covariance))
            nees.append(np.einsum("nia,nij,nja->n", error, p_inv, error))  # 4 degrees of freedom per track
    mean = float(np.mean(nees))
    dof = 4 * n * len(nees)
    low, high = stats.chi2.ppf([0.005, 0.995], dof) / (n * len(nees))
    assert low <= mean <= high, f"mean NEES {mean:.3f} outside [{low:.3f}, {high:.3f}]"

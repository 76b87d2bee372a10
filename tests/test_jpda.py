"""JPDA's association core: the paper's example, brute force, normalisation, K-best convergence."""

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from trackers.jpda import _all_events, _factors, association_probabilities


def test_the_papers_two_by_two_example():
    # Eq. 14: z1 may be target 1's or clutter, z2 target 2's or clutter; four joint events (eq. 15).
    # Likelihoods chosen so the events have the paper's probabilities (eq. 16): 0.0000, 0.0001, 0.9999, 0.0000.
    g = np.array([[1000.0, 0.0], [0.0, 10 / 9]])
    pd, lam = 0.9, 1e-3
    w1, w2, miss = pd * g[0, 0] / lam, pd * g[1, 1] / lam, 1 - pd
    events = {"none": miss * miss, "z1": w1 * miss, "both": w1 * w2, "z2": miss * w2}
    total = sum(events.values())
    p = {k: v / total for k, v in events.items()}
    assert [round(p[k], 4) for k in ("none", "z1", "both", "z2")] == [0.0, 0.0001, 0.9999, 0.0]
    beta = association_probabilities(g, pd, lam)
    expected = [[p["none"] + p["z2"], p["z1"] + p["both"], 0.0], [p["none"] + p["z1"], 0.0, p["both"] + p["z2"]]]
    np.testing.assert_allclose(beta, expected, rtol=1e-12)
    np.testing.assert_allclose(np.round(beta[:, 1:].T, 4), [[1.0, 0.0], [0.0, 0.9999]])  # eq. 17, measurements x targets
    assert round(beta[1, 0], 4) == 0.0001 and len(_all_events(*_factors(g, pd, lam))) == 4


@st.composite
def problems(draw):
    n, m = draw(st.integers(1, 4)), draw(st.integers(0, 4))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    g = rng.exponential(1.0, (n, m)) * (rng.random((n, m)) < 0.7)
    return g, draw(st.sampled_from([0.5, 0.9, 0.99])), draw(st.sampled_from([0.05, 1.0, 3.0]))


def brute_force(g, pd, lam):
    """Every way to give each target a distinct measurement or none, weighted as in eq. 8."""
    n, m = g.shape
    beta, total = np.zeros((n, m + 1)), 0.0
    for choice in itertools.product(range(-1, m), repeat=n):
        used = [j for j in choice if j >= 0]
        if len(used) != len(set(used)):
            continue
        weight = np.prod([(1 - pd) if j < 0 else pd * g[t, j] / lam for t, j in enumerate(choice)])
        total += weight
        for t, j in enumerate(choice):
            beta[t, j + 1] += weight
    return beta / total


@settings(max_examples=200, deadline=None)
@given(problems())
def test_exact_matches_brute_force_and_rows_sum_to_one(problem):
    g, pd, lam = problem
    beta = association_probabilities(g, pd, lam)
    np.testing.assert_allclose(beta, brute_force(g, pd, lam), rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(beta.sum(axis=1), 1.0)


@settings(max_examples=100, deadline=None)
@given(problems())
def test_k_best_converges_to_exact_and_equals_it_with_every_event(problem):
    g, pd, lam = problem
    exact = association_probabilities(g, pd, lam)
    n_events = len(_all_events(*_factors(g, pd, lam)))
    errors = [np.abs(association_probabilities(g, pd, lam, k=k) - exact).max() for k in range(1, n_events + 1)]
    assert errors[-1] < 1e-9
    np.testing.assert_allclose(association_probabilities(g, pd, lam, k=n_events + 5), exact, atol=1e-12)
    assert errors[-1] <= errors[0] + 1e-12


def test_bad_inputs():
    with pytest.raises(ValueError, match="non-negative"):
        association_probabilities(np.array([[-1.0]]), 0.9, 1.0)
    with pytest.raises(ValueError, match=r"pd must lie in \[0, 1\]"):
        association_probabilities(np.ones((1, 1)), 1.5, 1.0)
    with pytest.raises(ValueError, match="clutter_density must be positive"):
        association_probabilities(np.ones((1, 1)), 0.9, 0.0)
    with pytest.raises(ValueError, match="positive integer"):
        association_probabilities(np.ones((1, 1)), 0.9, 1.0, k=0)
    with pytest.raises(ValueError, match="no joint event"):
        association_probabilities(np.zeros((1, 1)), 1.0, 1.0)

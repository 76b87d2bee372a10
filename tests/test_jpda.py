"""JPDA's association core: the paper's example, brute force, normalisation, K-best convergence."""

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mtt_sim.trackers.jpda import _all_events, _factors, association_probabilities


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


@settings(max_examples=150, deadline=None)
@given(problems(), st.integers(1, 12))
def test_murty_finds_the_k_heaviest_joint_events(problem, k):
    """The enumeration shortcut for small clusters and Murty agree on which events are the k best."""
    from mtt_sim.trackers.jpda import _best_events
    w, miss = _factors(*problem)
    heaviest = sorted((weight for _, weight in _all_events(w, miss)), reverse=True)[:k]
    found = [weight for _, weight in _best_events(w, miss, k)]
    scale = heaviest[0] if heaviest else 1.0
    np.testing.assert_allclose(np.array(found) * scale, heaviest, rtol=1e-9)  # Murty's weights are relative


def test_bad_inputs():
    with pytest.raises(ValueError, match="non-negative"):
        association_probabilities(np.array([[-1.0]]), 0.9, 1.0)
    with pytest.raises(ValueError, match=r"pd must lie in \[0, 1\]"):
        association_probabilities(np.ones((1, 1)), 1.5, 1.0)
    with pytest.raises(ValueError, match="clutter_density must be positive"):
        association_probabilities(np.ones((1, 1)), 0.9, 0.0)
    with pytest.raises(ValueError, match="positive integer"):
        association_probabilities(np.ones((1, 1)), 0.9, 1.0, k=0)
    with pytest.raises(ValueError, match="budget must be None"):
        association_probabilities(np.ones((1, 1)), 0.9, 1.0, budget=0)
    with pytest.raises(ValueError, match="no joint event"):
        association_probabilities(np.zeros((1, 1)), 1.0, 1.0)


# ------------------------------------------------------------------ motion situations and the tracker

from mtt_sim import trackers  # noqa: E402
from mtt_sim.trackers.jpda import NEW, NORMAL, OCCLUDED, REVIVED, SEPARATED, SPLIT, VANISHED, situations  # noqa: E402


def test_situations_from_beta_prime():
    # rows: measurements z0..z4; columns: targets t0..t4
    b = np.zeros((5, 5))
    b[0, 0] = 0.9            # t0 normal: z0 is its only measurement and z0 is only t0's
    b[1, 1] = b[2, 1] = 0.4  # t1 split into z1 and z2
    b[3, 2] = 0.6            # t2 and t3 merged into z3: occluded (Table 1's row with several positive entries)
    b[3, 3] = 2.8e-8
    # t4: no measurement -> vanished; z4: no target -> new
    situ, new = situations(b)
    assert situ == [NORMAL, SPLIT, OCCLUDED, OCCLUDED, VANISHED] and new.tolist() == [4]


def frames(paths, k_max):
    """Observations from per-target paths of centres (x, y), boxes 10 x 20, or (x, y, w, h); None = not detected."""
    for k in range(k_max):
        rows = [(x - w / 2, y - h / 2, w, h, 0.9) for p in paths if (c := p(k)) is not None
                for x, y, w, h in [tuple(c) + (10, 20)[len(c) - 2:]]]
        dets = np.zeros((8, 5), np.float32)
        dets[: len(rows)] = np.array(rows, np.float32).reshape(-1, 5)
        yield {"detections": dets, "num_detections": len(rows)}


PAPER = {"min_hits": 1, "coast": False, "early_duplicates": False, "blob_report": "all",  # its track management
         "merge_needs_overlap": False}


def run(paths, k_max, **params):
    t = trackers.make("jpda", **params)
    t.reset({})
    return t, [(tr.ids.tolist(), list(t.last["situations"])) for tr in map(t.update, frames(paths, k_max))]


def test_new_then_normal_then_vanished_and_ended_after_three_misses():
    a = lambda k: (20 + 2 * k, 50) if k < 10 else None  # noqa: E731
    t, out = run([a], 16, **PAPER)
    assert out[0] == ([1], [NEW]) and out[5] == ([1], [NORMAL])
    assert [o[1] for o in out[10:13]] == [[VANISHED]] * 3 and all(o[0] == [] for o in out[10:])
    assert len(t.tracks) == 0 and t.ended.ids.tolist() == [1]


def test_a_confirmed_target_stays_confirmed_through_a_miss():
    a = lambda k: (20 + 2 * k, 50) if k != 10 else None  # noqa: E731 (one missed detection)
    _, out = run([a], 14, min_hits=3, coast=False)
    assert [o[0] for o in out[:4]] == [[], [], [1], [1]]  # confirmed at its third frame
    assert out[10][0] == [] and out[11][0] == [1]  # not re-counted: back at once after the miss


def test_with_coast_a_confirmed_target_is_reported_while_missed_until_it_vanishes():
    a = lambda k: (20 + 2 * k, 50) if k < 10 else None  # noqa: E731
    _, out = run([a], 15, min_hits=3, coast=True)
    assert [o[0] for o in out[10:15]] == [[1], [1], [], [], []]  # coasts 2 frames, ended at the third miss
    _, out = run([a], 15, min_hits=3, coast=False)
    assert [o[0] for o in out[10:15]] == [[]] * 5  # the paper's: only targets with a measurement this frame


@pytest.mark.parametrize("fix", [{"early_duplicates": True}, {"occlusion_covariance": "full"}])
def test_a_duplicate_born_beside_its_target_does_not_cost_the_target_its_id(fix):
    a = lambda k: (20 + 5 * k, 50)  # noqa: E731
    dup = lambda k: (20 + 5 * k, 56) if k == 15 else None  # noqa: E731 (one stray detection, just outside the gate)
    _, out = run([a, dup], 30, meas_sigma=1.0, **PAPER)
    assert out[17][1] == [OCCLUDED, OCCLUDED] and out[-1][0] == [3]  # the paper's rule: snapped at rest, then lost
    _, out = run([a, dup], 30, meas_sigma=1.0, **PAPER | fix)
    assert out[15][0] == [1, 2] and all(o[0] == [1] for o in out[16:])


def test_a_target_reappearing_soon_is_revived_with_its_id():
    a = lambda k: (20 + 2 * k, 50) if not 10 <= k < 14 else None  # noqa: E731 (4 frames missed: ended, then back)
    t, out = run([a], 20)
    assert out[13][0] == [] and out[14] == ([1], [REVIVED])
    assert t.tracks.next_id == 2  # no new target was started


def test_a_target_reappearing_too_late_is_new():
    a = lambda k: (20 + 2 * k, 50) if not 10 <= k < 20 else None  # noqa: E731
    t, out = run([a], 24, **PAPER)
    assert out[20][0] == [2] and out[20][1] == [NEW]


def test_fragments_of_one_target_are_a_split_and_update_it():
    def halves(sign):
        return lambda k: (20 + 2 * k, 50 + sign * 4) if k >= 10 else ((20 + 2 * k, 50) if sign > 0 else None)
    t, out = run([halves(1), halves(-1)], 14)
    assert out[10][1] == [SPLIT] and out[12][0] == [1]  # one target, not two
    assert abs(t.tracks.kf.x[0, 1] - 50) < 2  # the combined update sits between the fragments


def test_two_targets_merging_into_one_blob_are_occluded_and_sit_at_the_blob():
    a = lambda k: (20 + 2 * k, 50) if k < 8 else (None if k < 12 else (20 + 2 * k, 50))  # noqa: E731
    b = lambda k: (20 + 2 * k, 80) if k < 8 else ((20 + 2 * k, 65) if k < 12 else (20 + 2 * k, 80))  # noqa: E731
    t, out = run([a, b], 9, meas_sigma=8.0, **PAPER)  # the paper's rule: at the blob, at rest
    assert out[8][1] == [OCCLUDED, OCCLUDED] and sorted(out[8][0]) == [1, 2]
    np.testing.assert_allclose(t.tracks.kf.x[:, :2], [[36, 65], [36, 65]], atol=1e-9)
    np.testing.assert_allclose(t.tracks.kf.x[:, 2:], 0.0)


def test_two_targets_apart_sharing_one_measurement_are_not_merged():
    """One detection between two targets whose boxes do not touch (the other detection missed) is no merge: the
    JPDA update stands and both keep their velocities (the paper's rule snaps both to it, at rest)."""
    a = lambda k: (20 + 2 * k, 50) if k != 8 else None  # noqa: E731
    b = lambda k: (20 + 2 * k, 80) if k != 8 else (36, 65)  # noqa: E731
    t, out = run([a, b], 9, meas_sigma=8.0)
    assert out[8][1] == [NORMAL, NORMAL] and sorted(out[8][0]) == [1, 2]
    assert (np.abs(t.tracks.kf.x[:, 2]) > 1).all()
    t, out = run([a, b], 9, meas_sigma=8.0, merge_needs_overlap=False)
    assert out[8][1] == [OCCLUDED, OCCLUDED]


def test_jpda_exact_uses_every_joint_event():
    exact, approx = trackers.make("jpda_exact"), trackers.make("jpda")
    assert exact._k(3, 4) is None and approx._k(3, 4) == 7 and exact._k(9, 9) == 5000
    assert exact._budget() == 5000 and approx._budget() is None  # the budget: jpda_exact's alone


@pytest.mark.parametrize("name", ["jpda", "jpda_exact"])
def test_end_to_end_through_gym_make(name):
    from test_trackers import EASY, checked_episode, run_episode
    assert run_episode(name, "mtt_sim/ClutterStorm-v0", EASY)["MOTA"] >= 0.95
    m = checked_episode(name, "mtt_sim/Soccer-v0", {"env.max_steps": 30})
    # seed 0 as measured (660 ground-truth boxes, the K best events giving the exact answer); more than 0.03 off is a
    # change to look at
    assert m["num_frames"] == 30 and (m["MOTA"], m["IDF1"]) == pytest.approx((0.85, 0.921), abs=0.03)


def crossing_paths():
    """A walks right, B left, 8 px apart vertically; for frames 9-11 the detector sees one merged blob."""
    a = lambda k: (20 + 3 * k, 50)  # noqa: E731
    b = lambda k: (80 - 3 * k, 58)  # noqa: E731
    merged = range(9, 12)
    return ([lambda k: a(k) if k not in merged else ((a(k)[0] + b(k)[0]) / 2, 54),
             lambda k: b(k) if k not in merged else None], a, b)


def test_occlusion_merge_then_separation_keeps_ids():
    paths, a, b = crossing_paths()
    t = trackers.make("jpda", occlusion_velocity="keep")  # with the paper's zero velocity the two states are equal
    t.reset({})
    owner = {}
    for k, obs in enumerate(frames(paths, 20)):
        tracks = t.update(obs)
        if k == 9:
            assert t.last["situations"] == [OCCLUDED, OCCLUDED]
        if k == 12:
            assert t.last["situations"] == [SEPARATED, SEPARATED]  # one measurement each as they come apart
        centres = tracks.boxes[:, :2] + tracks.boxes[:, 2:] / 2
        if k not in range(9, 12):
            for tid, c in zip(tracks.ids.tolist(), centres):
                who = "a" if np.hypot(*(c - a(k))) < np.hypot(*(c - b(k))) else "b"  # the nearer target
                owner.setdefault(tid, set()).add(who)
    # each target keeps its own velocity through the merge, so both come out on their own side with their ids
    assert owner == {1: {"a"}, 2: {"b"}}, owner


@pytest.mark.parametrize("blob, reported", [((10, 20), [[1]] * 3), ((20, 20), [[1, 2]] * 3)])
def test_a_merged_blob_reports_as_many_targets_as_its_box_holds(blob, reported):
    """blob_report=size: two targets merge into one detection for frames 9-11. A blob the size of one target
    reports one (the elder), a blob twice that size both; either way both come out with their ids."""
    paths, a, b = crossing_paths()
    paths[0] = lambda k: a(k) if k not in range(9, 12) else ((a(k)[0] + b(k)[0]) / 2, 54) + blob
    for params, expected in [({}, reported), ({"blob_report": "all"}, [[1, 2]] * 3)]:  # all: the paper's
        t = trackers.make("jpda", occlusion_velocity="keep", **params)
        t.reset({})
        out = [sorted(t.update(obs).ids.tolist()) for obs in frames(paths, 16)]
        assert out[9:12] == expected and out[8] == out[12] == out[15] == [1, 2]


def test_bad_occlusion_velocity():
    with pytest.raises(ValueError, match="occlusion_velocity='stop': allowed: 'keep', 'zero'"):
        trackers.make("jpda:occlusion_velocity=stop")


def test_a_duplicate_sharing_one_blob_for_long_is_dropped():
    """Two targets that sit in one blob for merge_frames frames are one object: the younger goes."""
    a = lambda k: (20 + 2 * k, 50) if k < 3 else (20 + 2 * k, 54)  # noqa: E731
    b = lambda k: (20 + 2 * k, 58) if k < 3 else None  # noqa: E731  (merged into a's blob from frame 3 on)
    t, out = run([a, b], 30, meas_sigma=6.0, merge_frames=10, **PAPER)
    assert out[5][1] == [OCCLUDED, OCCLUDED] and len(t.tracks) == 1 and out[-1][0] == [1]


# ------------------------------------------------------------------ jpda_exact's budget (issue 37)

# the tuning draw that ran over 30 minutes on one sequence: a 50 px meas_sigma, so every gate takes in every detection
WIDE = {"meas_sigma": 49.77, "gate_probability": 0.9703, "accel_sigma": 1.34, "speed_sigma0": 10.9, "pd": 0.917,
        "clutter_density": 4.1e-5, "min_hits": 2, "vanish_frames": 1}


def counting_events(monkeypatch, stop_after):
    """Count the joint events the enumeration lists; fail (rather than hang) once it lists more than `stop_after`."""
    from mtt_sim.trackers import jpda
    listed, original = [], jpda._joint_events

    def counted(w, miss):
        listed.append(0)
        for event in original(w, miss):
            listed[-1] += 1
            assert listed[-1] <= stop_after, "the enumeration ran past the budget"
            yield event

    monkeypatch.setattr(jpda, "_joint_events", counted)
    return listed


def test_a_cluster_over_the_budget_lists_one_event_past_it_then_takes_murtys_best(monkeypatch):
    """8 targets and 12 measurements, all in one gate: about 10^9 joint events. With a budget of 300 the listing stops
    at the 301st and the cluster gets its 300 most probable events, exactly what k=300 (Murty) gives."""
    g = np.random.default_rng(7).uniform(0.5, 2.0, (8, 12))
    listed = counting_events(monkeypatch, 301)
    beta = association_probabilities(g, 0.9, 1.0, budget=300)
    assert listed == [301]
    np.testing.assert_array_equal(beta, association_probabilities(g, 0.9, 1.0, k=300))
    assert np.isfinite(beta).all() and np.allclose(beta.sum(axis=1), 1.0)
    assert _all_events(*_factors(g, 0.9, 1.0), limit=300) is None


@settings(max_examples=150, deadline=None)
@given(problems())
def test_below_the_budget_it_is_the_exact_enumeration_and_over_it_the_budgets_best(problem):
    g, pd, lam = problem
    n_events = len(_all_events(*_factors(g, pd, lam)))
    exact = association_probabilities(g, pd, lam)
    np.testing.assert_allclose(exact, brute_force(g, pd, lam), rtol=1e-9, atol=1e-12)
    for budget in (n_events, n_events + 1, 10**6):   # at or below the budget: the same numbers, to the bit
        np.testing.assert_array_equal(association_probabilities(g, pd, lam, budget=budget), exact)
    if n_events > 1:
        np.testing.assert_array_equal(association_probabilities(g, pd, lam, budget=n_events - 1),
                                      association_probabilities(g, pd, lam, k=n_events - 1))


def test_jpda_exact_with_wide_gates_stops_at_its_budget(monkeypatch):
    """The tuning draw's wide gates on a crowd: 9 people 12 px apart, then 14 detections among them. Every cluster
    of the second frame stops listing at max_events + 1 and is ranked by Murty instead."""
    from mtt_sim.trackers import jpda
    ranked = []
    best_events = jpda._best_events
    monkeypatch.setattr(jpda, "_best_events", lambda w, miss, k: ranked.append((w.shape, k)) or best_events(w, miss, k))
    tracker = trackers.make("jpda_exact", **WIDE, max_exact_targets=9, max_events=200)
    tracker.reset({})
    rng = np.random.default_rng(3)

    def obs(centres):
        dets = np.zeros((16, 5), np.float32)
        dets[: len(centres)] = [(x - 10, y - 20, 20, 40, 0.9) for x, y in centres]
        return {"detections": dets, "num_detections": len(centres)}

    tracker.update(obs([(100 + 12 * i, 100) for i in range(9)]))
    listed = counting_events(monkeypatch, 201)
    tracks = tracker.update(obs(np.c_[rng.uniform(90, 210, 14), rng.uniform(90, 110, 14)]))
    assert listed and all(n == 201 for n in listed)              # each listing stopped one past the budget
    assert ranked and all(k == 200 and shape == (9, 14) for shape, k in ranked)
    assert np.isfinite(tracks.boxes).all()

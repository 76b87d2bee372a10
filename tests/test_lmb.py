"""The LMB tracker (Jiang and Yang) and the GM-PHD comparator: formulas with known answers, a plain
Kalman filter, brute-force enumeration of hypotheses, and runs through gym.make."""

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mtt_sim import trackers
from helpers import placed, run_tracker, still, tiny
from mtt_sim.env import TrackingEnv
from mtt_sim.trackers.parts import gaussian_mixture as gm
from mtt_sim.trackers.lmb import group_update

INFO = {"image_size": (640, 480)}


def obs_of(*rows):
    """An observation with detection rows (x, y, w, h, confidence)."""
    dets = np.zeros((8, 5), np.float32)
    if rows:
        dets[: len(rows)] = rows
    return {"detections": dets, "num_detections": len(rows)}


def test_single_target_with_certain_detection_and_no_clutter_is_a_kalman_filter():
    lmb = trackers.make("lmb", detection=1.0, survival=1.0, clutter_rate=1e-6, reid=False)
    lmb.reset(INFO)
    noise = gm.BoxNoise(lmb.params["measurement_noise"], lmb.params["process_noise"])
    rng = np.random.default_rng(0)
    truth = np.array([100.0, 80.0, 30.0, 60.0])
    x = P = None
    for k in range(15):
        z = (truth + [2.0 * k, 1.0 * k, 0, 0] + rng.normal(0, 1.5, 4)).astype(np.float32).astype(float)
        if x is None:   # the plain filter: born at the first detection, which does not also correct it
            x, P = noise.birth(z[None])
            x, P = x[0], P[0]
        else:
            x = gm.F @ x
            P = gm.F @ P @ gm.F.T + noise.process_covariance(x[None])[0]
            S = gm.H @ P @ gm.H.T + noise.measurement_covariance(x[None])[0]
            K = P @ gm.H.T @ np.linalg.inv(S)
            x, P = x + K @ (z - gm.H @ x), (np.eye(gm.DIM) - K @ gm.H) @ P
        tracks = lmb.update(obs_of([*z, 0.9]))
        assert len(tracks.ids) == 1 and tracks.ids[0] == 1
        np.testing.assert_allclose(tracks.boxes[0], x[:4], rtol=1e-6)
        np.testing.assert_allclose(lmb.tracks.m[0], x, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(lmb.tracks.P[0], P, rtol=1e-9, atol=1e-9)


def test_first_frame_detections_become_tracks_at_their_birth_existence_not_updated_by_themselves():
    """Sec. 4.2.1: at k = 1 every detection becomes a track, with r_B = birth_max x confidence; a 0.1-confidence box
    is not raised by its own detection (it was reported at r = 0.995)."""
    lmb = trackers.make("lmb", reid=False)
    lmb.reset(INFO)
    tracks = lmb.update(obs_of([100, 100, 30, 60, 0.1], [300, 200, 30, 60, 0.9]))
    np.testing.assert_allclose(lmb.tracks.r, [0.06, 0.54])
    np.testing.assert_allclose(lmb.tracks.m[:, :4], [[100, 100, 30, 60], [300, 200, 30, 60]])
    assert tracks.ids.tolist() == [2] and len(lmb.pending[0]) == 0   # only r > 0.5 is reported; no second birth


@pytest.mark.parametrize("birth", ["adaptive", "fixed"])
def test_the_reid_pool_holds_ten_features_per_target_detected_in_the_first_frame(birth):
    """Sec. 4.4: tp = tnum x T; fixed birth's 16 border components at frame 1 are not targets."""
    lmb = trackers.make("lmb", birth=birth)
    lmb.reset(INFO)
    lmb.update({**obs_of([100, 100, 30, 60, 0.9], [300, 200, 30, 60, 0.9], [500, 300, 30, 60, 0.4]),
                "frame": np.zeros((480, 640, 3), np.uint8)})
    assert lmb.pool.items.maxlen == 30


def test_existence_decays_with_misses_at_the_rate_of_the_formula():
    lmb = trackers.make("lmb", detection=0.8, survival=0.95, prune=1e-9, reid=False)
    lmb.reset(INFO)
    lmb.update(obs_of([100, 100, 30, 60, 0.9]))
    r = lmb.tracks.r[0]
    rates = []
    for _ in range(6):
        lmb.update(obs_of())
        r_pred = 0.95 * r
        expected = r_pred * 0.2 / (1 - r_pred * 0.8)        # missed: r (1 - P_D) / (1 - r P_D) after survival
        assert lmb.tracks.r[0] == pytest.approx(expected, rel=1e-12)
        rates.append(expected / r)
        r = expected
    assert all(a > b for a, b in zip(rates, rates[1:]))     # the less certain, the faster it fades... relatively


def test_without_coasting_a_missed_track_is_not_reported_but_lives_on_with_its_label():
    """coast=false (the ablation of the README's decomposition) hides a track the frame it is missed; the filter
    itself is unchanged, so the track comes back under its label at the next detection."""
    boxes = [[100.0 + 3 * k, 100, 30, 60, 0.9] for k in range(6)]
    runs = {}
    for coast in (True, False):
        lmb = trackers.make("lmb", reid=False, coast=coast)
        lmb.reset(INFO)
        runs[coast] = [lmb.update(obs_of(*([] if k == 3 else [b]))).ids.tolist() for k, b in enumerate(boxes)]
    assert runs[True] == [[1]] * 6
    assert runs[False] == [[1], [1], [1], [], [1], [1]]


def test_existence_rises_with_detections_at_the_rate_of_the_formula_and_a_birth_needs_an_unexplained_one():
    lmb = trackers.make("lmb", reid=False, clutter_rate=50.0, prune=0.05)  # no second birth at the same place
    lmb.reset(INFO)
    assert len(lmb.update(obs_of()).ids) == 0
    assert len(lmb.update(obs_of([300, 200, 30, 60, 0.3])).ids) == 0   # pending birth, nothing to report yet
    assert lmb.pending[1] == pytest.approx([0.6 * 0.3])                  # r_B = birth_max x confidence
    p, t = lmb.params, lmb.tracks
    history = []
    for k in range(4):
        z = np.array([[300.0 + k, 200, 30, 60]])
        if len(t.r):   # on the track's own predicted Gaussian: (r pD q / k + r (1 - pD)) / (r pD q / k + 1 - r pD)
            m, P = gm.predict(t.m, t.P, lmb.noise)
            inn = gm.Innovation.of(m, P, lmb.noise)
            q = np.exp(inn.log_likelihood(inn.distance2(z))[0, 0] - lmb.log_clutter_density)
            r, pd = p["survival"] * t.r[0], p["detection"]
            expected = (r * pd * q + r * (1 - pd)) / (r * pd * q + 1 - r * pd)
        lmb.update(obs_of([*z[0], 0.3]))
        if k:
            assert t.r[0] == pytest.approx(expected, rel=1e-9)
        history.append(t.r[0])
    assert history[0] > 0.6 * 0.3 and min(history) > 0.99   # up from r_B at the first hit, then held near one
    assert len(lmb.pending[0]) == 0    # an explained detection gives no birth


@pytest.mark.parametrize("rule, expected", [("confidence", [0.3, 0.6]), ("reuter", [0.5, 0.5]),
                                             ("reuter_confidence", [0.25, 0.5])])
def test_birth_rules_give_their_formulas_existence(rule, expected):
    """Two unexplained detections (confidences 0.5 and 1): ours, birth_max x confidence; Reuter et al.'s eq. 75,
    min(birth_max, lambda_B (1 - r_U) / sum (1 - r_U)) with lambda_B = 1; and that times the confidence."""
    lmb = trackers.make("lmb", reid=False, birth_rule=rule, birth_rate=1.0, birth_max=0.6)
    lmb.reset(INFO)
    lmb.update(obs_of())
    lmb.update(obs_of([100, 100, 30, 60, 0.5], [300, 200, 30, 60, 1.0]))
    np.testing.assert_allclose(lmb.pending[1], expected)
    np.testing.assert_allclose(lmb._birth_existence(np.array([1.0, 0.5, 0.0]), np.ones(3)),
                               {"confidence": [0.6, 0.3, 0.0]}.get(rule, [0.6, 1 / 3, 0.0]))


def brute_force_beta(log_r, log_q, pd):
    """Every joint hypothesis of a group enumerated: each track takes a distinct measurement, is missed or is dead."""
    n, m = log_q.shape
    r = np.exp(log_r)
    beta, total = np.zeros((n, m + 1)), 0.0
    for choice in itertools.product(range(m + 2), repeat=n):
        taken = [c for c in choice if c < m]
        if len(taken) != len(set(taken)):
            continue
        w = 1.0
        for i, c in enumerate(choice):
            w *= r[i] * pd * np.exp(log_q[i, c]) if c < m else (r[i] * (1 - pd) if c == m else 1 - r[i])
        total += w
        for i, c in enumerate(choice):
            if c <= m:
                beta[i, c] += w
    return beta / total


@pytest.mark.parametrize("seed", range(4))
def test_group_update_equals_enumeration_and_grouping_changes_nothing(seed):
    rng = np.random.default_rng(seed)
    log_r = np.log(rng.uniform(0.2, 0.95, 4))
    log_q = rng.normal(1.0, 1.5, (4, 3))
    log_q[:2, 2] = log_q[2:, :2] = -np.inf      # two groups: tracks 0, 1 with z0, z1; tracks 2, 3 with z2
    full = group_update(log_r, log_q, 0.8, hypotheses=1000)
    np.testing.assert_allclose(full, brute_force_beta(log_r, log_q, 0.8), atol=1e-12)
    first = group_update(log_r[:2], log_q[:2, :2], 0.8, hypotheses=1000)
    second = group_update(log_r[2:], log_q[2:, 2:], 0.8, hypotheses=1000)
    np.testing.assert_allclose(full[:2, [0, 1, 3]], first, atol=1e-12)
    np.testing.assert_allclose(full[2:, [2, 3]], second, atol=1e-12)
    one = group_update(log_r[:1], log_q[:1, :2], 0.8, hypotheses=1000)   # the closed form of a lone track
    np.testing.assert_allclose(one, brute_force_beta(log_r[:1], log_q[:1, :2], 0.8), atol=1e-12)


@pytest.mark.parametrize("seed", range(10))
def test_group_update_through_murty_equals_brute_force_and_enumeration(seed, monkeypatch):
    """Groups too large to enumerate go through Murty's k best: with every hypothesis kept it equals brute force; with
    the 15 best kept it equals enumerating all and keeping the same 15."""
    rng = np.random.default_rng(seed)
    n, m = (4, 3) if seed < 5 else (6, 5)
    log_r = np.log(rng.uniform(0.2, 0.95, n))
    log_q = np.where(rng.random((n, m)) < 0.7, rng.normal(1.0, 1.5, (n, m)), -np.inf)
    enumerated = group_update(log_r, log_q, 0.8, hypotheses=15)
    monkeypatch.setattr("mtt_sim.trackers.lmb.ENUMERATE_UP_TO", 0)
    np.testing.assert_allclose(group_update(log_r, log_q, 0.8, hypotheses=15), enumerated, atol=1e-12)
    if n == 4:
        np.testing.assert_allclose(group_update(log_r, log_q, 0.8, hypotheses=10**4), brute_force_beta(log_r, log_q, 0.8),
                                   atol=1e-12)


def crossing_scene():
    walker = {"count": 1, "size": [30.0, 60.0], "size_jitter": 0.0, "speed": 2.0, "speed_jitter": 0.0,
              "heading_jitter": 0.0, "accel": 0.0}
    return tiny(groups=[{**walker, "name": "a", "heading": 0.0, "region": [0.1, 0.45, 0.101, 0.451]},
                        {**walker, "name": "b", "heading": 180.0, "region": [0.9, 0.5, 0.901, 0.501]}],
                render={"width": 300, "height": 150}, world={"walls": False, "collision": "none"},
                env={"max_steps": 110})


@pytest.mark.parametrize("spec", ["lmb:reid=false", "gmphd"])
def test_labels_survive_a_crossing(spec):
    m, _ = run_tracker(spec, crossing_scene())
    assert m["IDSW"] == 0 and m["num_tracker_ids"] == 2 and m["MOTA"] > 0.9


def test_gmphd_cardinality_on_a_static_scene_converges_to_the_true_count():
    env = placed(tiny(groups=[still(count=3, size=(30.0, 30.0))]), [(40, 50), (100, 50), (160, 50)])
    obs = env.observe()
    phd = trackers.make("gmphd", detection=0.99)  # the scene's detector misses nothing
    phd.reset({"image_size": (200, 100)})
    counts, reported = [], []
    for _ in range(25):
        reported.append(len(phd.update(obs).ids))
        counts.append(phd.w.sum())
    assert counts[0] == 0 and reported[0] == 0               # births wait for the next frame
    assert np.allclose(counts[-10:], 3, atol=0.05) and reported[-10:] == [3] * 10


def random_mixture(seed: int, n: int, axis_aligned: bool = False):
    """n components clustered in a few places (so some merge), with random positive-definite covariances; axis
    aligned: diagonal covariances and components that differ in x or in y alone, where the one-coordinate bound
    `within_distance` prunes with is exact."""
    rng = np.random.default_rng(seed)
    m = rng.uniform(0, 200, (n // 4 + 1, gm.DIM))[np.arange(n) // 4] + rng.normal(0, 3, (n, gm.DIM))
    a = rng.normal(0, 2, (n, gm.DIM, gm.DIM))
    P = a @ a.transpose(0, 2, 1) + np.eye(gm.DIM)
    if axis_aligned:
        m[:, 2:] = 0
        m[np.arange(n), rng.integers(0, 2, n)] = 0
        P = P * np.eye(gm.DIM)
    return rng.uniform(0.01, 1, n), m, P


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 10**6), st.integers(1, 40), st.floats(0.5, 20), st.booleans())
def test_within_distance_finds_exactly_the_pairs_brute_force_finds(seed, n, limit, axis_aligned):
    _, m, P = random_mixture(seed, n, axis_aligned)
    d = m[None, :, :] - m[:, None, :]
    brute = np.einsum("kni,kij,knj->kn", d, np.linalg.inv(P), d) <= limit
    near = gm.within_distance(m, P, limit)
    assert [sorted(c.tolist()) for c in near] == [np.flatnonzero(row).tolist() for row in brute]


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 10**6), st.integers(1, 30), st.integers(0, 30), st.booleans())
def test_gated_distances_are_the_full_distances_inside_the_gate(seed, n, m, axis_aligned):
    _, means, P = random_mixture(seed, n, axis_aligned)
    z = np.random.default_rng(seed).uniform(0, 200, (m, gm.MEAS))
    inn = gm.Innovation.of(means, P, gm.BoxNoise())
    full, gate = inn.distance2(z), 9.49
    assert np.array_equal(inn.distance2(z, gate), np.where(full < gate, full, np.inf))


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 10**6), st.integers(1, 40), st.integers(1, 12))
def test_gmphd_merge_is_vo_and_mas_greedy_merge(seed, n, cap):
    """Table II of Vo and Ma (2006), written out: the heaviest open component absorbs every open one within the
    merge distance, until max_components are made."""
    w, m, P = random_mixture(seed, n)
    phd = trackers.make("gmphd", merge=4.0, max_components=cap)
    phd._prune_and_merge(w, m, P, np.arange(n))
    open_, expected = np.ones(n, bool), []
    for k in np.argsort(-w, kind="stable"):
        if open_[k] and len(expected) < cap:
            d = m - m[k]
            near = open_ & (np.einsum("ni,ij,nj->n", d, np.linalg.inv(P[k]), d) <= 4.0)
            wn, total = w[near], w[near].sum()
            mean = wn @ m[near] / total
            s = m[near] - mean
            cov = (np.einsum("n,nij->ij", wn, P[near]) + np.einsum("n,ni,nj->ij", wn, s, s)) / total
            expected.append((total, k, mean, cov))
            open_ &= ~near
    expected.sort(key=lambda e: -e[0])
    assert phd.label.tolist() == [e[1] for e in expected]
    assert np.allclose(phd.w, [e[0] for e in expected], rtol=1e-12)
    assert np.allclose(phd.m, [e[2] for e in expected]) and np.allclose(phd.P, [e[3] for e in expected])


def test_lmb_end_to_end_through_gym_make_is_reproducible_and_needs_the_image_size():
    a, tracker = run_tracker("lmb", "mtt_sim/Crossing-v0", {"env.max_steps": 60}, obs_mode="frame+detections")
    b, _ = run_tracker("lmb", "mtt_sim/Crossing-v0", {"env.max_steps": 60}, obs_mode="frame+detections")
    assert a == b and a["MOTA"] > 0.5
    drawn = tracker.debug()
    assert {d["kind"] for d in drawn} == {"ellipse", "bar"} and all(0 <= d["value"] <= 1 for d in drawn if d["kind"] == "bar")
    with pytest.raises(ValueError, match="image size"):
        trackers.make("lmb").reset({})
    with pytest.raises(ValueError, match="birth='sometimes': allowed: 'adaptive', 'fixed'"):
        trackers.make("lmb:birth=sometimes").reset(INFO)


@pytest.mark.parametrize("reid, switches", [(True, 0), (False, 1)])
def test_reid_restores_the_label_of_a_target_that_was_hidden_long_enough_to_be_forgotten(reid, switches):
    # a walker passes behind a wide board: 45 frames without a detection, so its track is pruned; re-id gives the
    # track born when it comes out the label it had
    walker = {"name": "w", "count": 1, "size": [30.0, 60.0], "size_jitter": 0.0, "speed": 2.0, "speed_jitter": 0.0,
              "heading": 0.0, "heading_jitter": 0.0, "accel": 0.0, "region": [0.1, 0.5, 0.101, 0.501],
              "color": [40, 90, 200], "similarity": 1.0, "texture": "stripes"}
    sc = tiny(groups=[walker], occluders=[{"rect": [100.0, 20.0, 120.0, 110.0], "color": [120, 120, 120]}],
              sensor={"min_visibility": 0.5}, render={"width": 300, "height": 150, "background": "noise"},
              world={"walls": False}, env={"max_steps": 115})
    env = TrackingEnv(sc, obs_mode="frame+detections")
    obs, info = env.reset(seed=0)
    tracker = trackers.make("lmb", reid=reid)
    tracker.reset(info)
    hidden = 0
    while True:
        obs, _, term, trunc, info = env.step(tracker.update(obs).to_action(env.action_space))
        hidden += int(obs["num_detections"]) == 0
        if term or trunc:
            break
    m = info["metrics"]
    assert hidden >= 40 and m["IDSW"] == switches and m["num_tracker_ids"] == 1 + switches


# ------------------------------------------------------------------ diverged components (issue 37)

# Ends of the search ranges that let a component run away on ETH-Bahnhof (a box at x = -657 in a 640 px image, frame
# 478: outside the action space, so a tuning trial failed)
RUNAWAY = dict(reid=False, survival=0.999, extract=0.2, process_noise=0.1, measurement_noise=0.05, gate=0.9999,
               detection=0.4)


def test_a_track_coasting_out_of_the_picture_is_dropped_before_its_box_leaves_the_action_space():
    """A large, fast target leaves on the left: with RUNAWAY's parameters its track coasts on at r > extract and ran
    an image beyond the border (reported at x = -658, -718, ...); its component is dropped there instead."""
    env = TrackingEnv(tiny(render={"width": 640, "height": 480}))
    lmb = trackers.make("lmb", **RUNAWAY)
    lmb.reset(INFO)
    x, reported = 300.0, []
    for _ in range(30):
        tracks = lmb.update(obs_of([x, 40, 160, 400, 1.0]) if x > -80 else obs_of())
        env.validate_action(tracks.to_action(env.action_space))  # raises ActionError outside the action space
        assert np.isfinite(tracks.boxes).all() and (tracks.boxes[:, 2:] > 0).all()
        reported += tracks.boxes[:, 0].tolist()
        assert not lmb_diverged(lmb).any()
        x -= 60
    assert min(reported) < -500  # it did coast far out (the guard is not what stopped it before)
    assert len(lmb.tracks.r) == 0  # and was dropped, not merely left unreported


def lmb_diverged(lmb):
    from mtt_sim.trackers.lmb import diverged
    return diverged(lmb.tracks.m, lmb.tracks.P, INFO["image_size"])


def test_diverged_flags_exactly_the_broken_components():
    from mtt_sim.trackers.lmb import diverged
    w, h = INFO["image_size"]
    good_m = np.array([100.0, 80.0, 30.0, 60.0, 1.0, 0.0, 0.0, 0.0])
    good_P = np.diag([4.0, 4.0, 4.0, 4.0, 1.0, 1.0, 0.1, 0.1])
    indefinite = good_P.copy()
    indefinite[0, 4] = indefinite[4, 0] = 3.0   # positive diagonal, a negative eigenvalue
    negative = good_P.copy()
    negative[5, 5] = -1.0
    cases = [  # (mean changes, covariance, diverged?)
        ({}, good_P, False),
        ({0: -w, 1: -h, 2: 2 * w, 3: 2 * h}, good_P, False),    # at the action space's edges
        ({0: 2 * w, 1: 2 * h}, good_P, False),
        ({0: np.nan}, good_P, True), ({5: np.inf}, good_P, True),
        ({}, np.where(np.eye(8, dtype=bool), good_P, np.nan), True),
        ({}, indefinite, True), ({}, negative, True), ({}, np.zeros((8, 8)), True),
        ({2: 0.0}, good_P, True), ({3: -5.0}, good_P, True),
        ({2: 2 * w + 1}, good_P, True), ({3: 1e9}, good_P, True),
        ({0: -w - 1}, good_P, True), ({1: 2 * h + 0.5}, good_P, True), ({0: 1e300}, good_P, True)]
    m = np.stack([np.array([changes.get(i, v) for i, v in enumerate(good_m)]) for changes, _, _ in cases])
    P = np.stack([c for _, c, _ in cases])
    np.testing.assert_array_equal(diverged(m, P, (w, h)), [d for _, _, d in cases])
    assert diverged(np.zeros((0, 8)), np.zeros((0, 8, 8)), (w, h)).shape == (0,)


def test_a_diverged_component_is_dropped_from_its_track_and_a_track_of_diverged_ones_with_it():
    """Hand-made: track 1 is healthy, track 2 has a healthy component and one an image beyond the left border, track
    3 only one far beyond it. After one update track 2 keeps its healthy component alone and track 3 is gone, though
    their existence stays high."""
    lmb = trackers.make("lmb", reid=False)
    lmb.reset(INFO)
    lmb.update(obs_of([100, 100, 30, 60, 0.9], [400, 100, 30, 60, 0.9]))
    t = lmb.tracks
    assert t.label.tolist() == [1, 2]
    m, P = lmb.noise.birth(np.array([[-2000.0, 100, 30, 60]]))
    t.add(np.array([0.9]), np.array([3]), m, P)       # track 3, alone and diverged
    t.track, t.w = np.r_[t.track[:2], 1, 2], np.r_[t.w[0], 0.6, 0.4, t.w[2]]   # track 2: its own and one far off
    t.m, t.P = np.concatenate([t.m[:2], m, t.m[2:]]), np.concatenate([t.P[:2], P, t.P[2:]])
    t.r[:] = 0.9
    tracks = lmb.update(obs_of([101, 100, 30, 60, 0.9], [401, 100, 30, 60, 0.9]))
    assert t.label.tolist() == [1, 2] and sorted(tracks.ids.tolist()) == [1, 2]
    assert np.bincount(t.track).tolist() == [1, 1] and np.allclose(t.w, 1.0)
    assert (t.m[:, 0] > 0).all() and np.isfinite(tracks.boxes).all()

"""Metrics: hand-computed answers, TrackEval's quirks, a cross-check against a dense re-statement, properties."""

import math
import tracemalloc

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import trackeval_reference as ref
from mtt_sim.metrics import METRICS, PER_TARGET, SUMMARY_FIELDS, EpisodeMetrics, evaluate, gospa

E = (np.zeros(0, int), np.zeros((0, 4)))


def frame(*rows):
    """(ids, boxes) from rows (id, x, y, w, h)."""
    if not rows:
        return E
    a = np.array(rows, float)
    return a[:, 0].astype(int), a[:, 1:]


A = (1, 0, 0, 10, 10)
B = (2, 100, 0, 10, 10)


def test_perfect_tracker_scores_one():
    gt = [frame(A, B)] * 5
    s = evaluate(gt, [frame((7, *A[1:]), (9, *B[1:]))] * 5)
    for k in ("MOTA", "MOTP", "IDF1", "IDP", "IDR", "HOTA", "DetA", "AssA", "LocA", "DetRe", "DetPr", "AssRe", "AssPr"):
        assert s[k] == pytest.approx(1.0), k
    assert (s["TP"], s["FP"], s["FN"], s["IDSW"], s["Frag"], s["MT"], s["GOSPA"]) == (10, 0, 0, 0, 0, 2, 0.0)
    assert (s["num_frames"], s["num_gt_dets"], s["num_gt_ids"]) == (5, 10, 2)


def test_all_miss_tracker():
    s = evaluate([frame(A, B)] * 4, [E] * 4, gospa_c=50.0, gospa_p=1.0)
    assert (s["MOTA"], s["IDF1"], s["HOTA"], s["DetA"]) == (0.0, 0.0, 0.0, 0.0)
    assert (s["FN"], s["ML"], s["MT"]) == (8, 2, 0)
    assert s["GOSPA"] == 50.0  # two misses at c / 2 each
    assert s["LocA"] == 1.0    # TrackEval's value when nothing matches


def test_single_id_swap():
    ok, swapped = frame((1, *A[1:]), (2, *B[1:])), frame((2, *A[1:]), (1, *B[1:]))
    s = evaluate([frame(A, B)] * 4, [ok, ok, swapped, swapped])
    assert s["IDSW"] == 2 and s["MOTA"] == pytest.approx((8 - 2) / 8)
    assert s["IDTP"] == 4 and s["IDF1"] == pytest.approx(0.5)
    assert s["AssA"] == pytest.approx(1 / 3) and s["HOTA"] == pytest.approx(math.sqrt(1 / 3))


def test_one_pixel_off():
    s = evaluate([frame(A)], [frame((1, 1, 0, 10, 10))])
    iou = 90 / 110
    assert s["MOTP"] == pytest.approx(iou)
    matched = np.arange(0.05, 0.99, 0.05) <= iou  # 16 of the 19 alphas
    assert matched.sum() == 16
    assert s["LocA"] == pytest.approx((16 * iou + 3 * 1.0) / 19)
    assert s["HOTA"] == pytest.approx(16 / 19)
    assert s["GOSPA"] == pytest.approx(1.0)
    assert (s["CentreError"], s["CentreErrorVar"]) == (1.0, 0.0)
    s = evaluate([frame(A)] * 2, [frame((1, 1, 0, 10, 10)), frame((1, 3, 0, 10, 10))])
    assert s["CentreError"] == pytest.approx(2.0) and s["CentreErrorVar"] == pytest.approx(1.0)


def test_per_target_centre_error_and_coverage():
    m = EpisodeMetrics()
    for f in range(4):  # target 1 matched 1 px off in all 4 frames; target 2 matched 3 px off in frames 0 and 1 only
        tracks = [(5, 1, 0, 10, 10)] + ([(6, 103, 0, 10, 10)] if f < 2 else [])
        m.update(*frame(A, B), *frame(*tracks))
    m.update(*frame((3, 50, 50, 10, 10)), *E)  # target 3: never matched
    per = m.per_target()
    none = {"HiddenCentreError": None, "Reacquired": None}   # no truth of hidden targets was passed
    assert per[1] == {"Coverage": 1.0, "CentreError": 1.0, **none} and per[2] == {"Coverage": 0.5, "CentreError": 3.0, **none}
    assert per[3]["Coverage"] == 0.0 and math.isnan(per[3]["CentreError"])
    assert m.summary()["CentreError"] == pytest.approx((4 * 1 + 2 * 3) / 6)


def test_previous_frame_not_last_ever_match_gets_the_bonus():
    # frame 1 misses A (a false track elsewhere keeps the frame from being skipped), so in frame 2 the
    # previous-timestep carry-over is empty: the better-overlapping new id 2 wins and that is a switch.
    far = (5, 300, 300, 10, 10)
    tracks = [frame((1, *A[1:])), frame(far), frame((1, 0, 3, 10, 10), (2, 0, 1, 10, 10))]
    s = evaluate([frame(A)] * 3, tracks)
    assert (s["IDSW"], s["TP"], s["FP"], s["FN"]) == (1, 2, 2, 1)


def test_a_frame_without_tracks_keeps_the_carry_over():
    # TrackEval skips a frame with no tracks before resetting the carry-over: id 1 keeps its bonus,
    # wins over the better-overlapping id 2, and no switch or new fragment is counted.
    tracks = [frame((1, *A[1:])), E, frame((1, 0, 3, 10, 10), (2, 0, 1, 10, 10))]
    s = evaluate([frame(A)] * 3, tracks)
    assert (s["IDSW"], s["Frag"], s["FN"], s["FP"]) == (0, 0, 1, 1)


def test_empty_frames_on_either_side():
    t = frame((3, *A[1:]))
    s = evaluate([E, frame(A), E, frame(A)], [t, t, E, E])
    assert (s["FP"], s["TP"], s["FN"], s["num_frames"], s["num_gt_dets"]) == (1, 1, 1, 4, 2)
    assert evaluate([E, E], [E, E])["MOTA"] == 0.0


def test_frag_and_mt_boundary():
    t = frame((1, *A[1:]))
    far = frame((9, 500, 500, 5, 5))
    s = evaluate([frame(A)] * 5, [t, t, far, t, t])  # tracked 4 of 5 = 80 %: PT, not MT
    assert (s["Frag"], s["MT"], s["PT"], s["ML"]) == (1, 0, 1, 0)
    s = evaluate([frame(A)] * 5, [t, far, far, far, far])  # 20 %: PT
    assert (s["MT"], s["PT"], s["ML"]) == (0, 1, 0)


def test_centroid_similarity():
    s = evaluate([frame(A)], [frame((1, 3, 4, 10, 10))], similarity="centroid", zero_distance=10.0)
    assert s["MOTP"] == pytest.approx(0.5)


def test_gospa_values():
    a, b = np.array([[0, 0, 2, 2.0]]), np.array([[3, 4, 2, 2.0]])
    assert gospa(a, b, c=50, p=1) == pytest.approx(5.0)
    assert gospa(a, b, c=4, p=2) == pytest.approx(4.0)  # cut off at c: min(5, 4)
    assert gospa(a, np.zeros((0, 4)), c=10, p=2) == pytest.approx(math.sqrt(50))


def test_bad_input_names_the_frame_and_the_problem():
    m = EpisodeMetrics()
    with pytest.raises(ValueError, match=r"frame 0: tracks boxes must be finite; row 0"):
        m.update([1], [[0, 0, 1, 1]], [1], [[0, 0, np.nan, 1]])
    with pytest.raises(ValueError, match=r"frame 0: gt ids must be unique"):
        m.update([1, 1], [[0, 0, 1, 1]] * 2, [], [])
    with pytest.raises(ValueError, match="gt has 2 frames but tracks has 1"):
        evaluate([E, E], [E])
    with pytest.raises(ValueError, match="similarity='giou'"):
        EpisodeMetrics(similarity="giou")


# ------------------------------------------------------------------ properties

def random_sequence(rng, n_frames, n_gt, spread=60.0):
    """Random GT tracks and noisy, sometimes swapped, sometimes missing tracks over `n_frames` frames."""
    pos = rng.uniform(0, spread, (n_gt, 2))
    gt, tracks = [], []
    for _ in range(n_frames):
        pos += rng.normal(0, 3, pos.shape)
        present = rng.random(n_gt) < 0.85
        boxes = np.c_[pos, np.full((n_gt, 2), 10.0)][present]
        ids = np.flatnonzero(present) * 7 + 3
        gt.append((ids, boxes))
        keep = rng.random(len(ids)) < 0.8
        tb = boxes[keep] + rng.normal(0, 1.5, (keep.sum(), 4)) * [1, 1, 0.3, 0.3]
        tid = rng.permutation(10)[: keep.sum()] if rng.random() < 0.3 else np.flatnonzero(keep) + 100
        extra = int(rng.integers(0, 3))  # false tracks
        tb = np.r_[tb, np.c_[rng.uniform(0, spread + 10, (extra, 2)), np.full((extra, 2), 10.0)]]
        tid = np.r_[tid, 1000 + np.arange(extra)]
        tracks.append((tid, tb))
    return gt, tracks


@st.composite
def sequences(draw):
    n_frames, n_gt = draw(st.integers(1, 8)), draw(st.integers(0, 5))
    return random_sequence(np.random.default_rng(draw(st.integers(0, 2**32 - 1))), n_frames, n_gt)


@settings(max_examples=150, deadline=None)
@given(sequences())
def test_matches_the_dense_trackeval_restatement(seq):
    gt, tracks = seq
    ours, theirs = evaluate(gt, tracks), ref.evaluate(gt, tracks)
    for key, value in theirs.items():
        assert ours[key] == pytest.approx(value, abs=1e-9), key


@settings(max_examples=60, deadline=None)
@given(sequences(), st.integers(0, 1000))
def test_invariant_to_renaming_ids_and_permuting_rows(seq, seed):
    gt, tracks = seq
    rng = np.random.default_rng(seed)

    def shuffle(frames, offset):
        out = []
        for ids, boxes in frames:
            p = rng.permutation(len(ids))
            out.append((ids[p] * 13 + offset, boxes[p]))
        return out

    a, b = evaluate(gt, tracks), evaluate(shuffle(gt, -50), shuffle(tracks, 99))
    for key in a:
        assert a[key] == pytest.approx(b[key], abs=1e-9), key


@settings(max_examples=60, deadline=None)
@given(sequences())
def test_bounds_and_incremental_equals_batch(seq):
    gt, tracks = seq
    m = EpisodeMetrics()
    for k, ((gi, gb), (ti, tb)) in enumerate(zip(gt, tracks)):
        stats = m.update(gi, gb, ti, tb)
        assert stats.tp + stats.fn == stats.num_gt == len(gi)
        assert m.summary() == evaluate(gt[: k + 1], tracks[: k + 1])  # summary never disturbs the state
    s = m.summary()
    assert s["MOTA"] <= 1 and 0 <= s["HOTA"] <= 1 and 0 <= s["IDF1"] <= 1 and s["GOSPA"] >= 0


def test_a_long_episode_matches_the_dense_restatement_and_every_frame_keeps_its_gospa():
    """Past the batches in which frames are stored (256), with crowded frames (boxes overlapping several others)."""
    gt, tracks = random_sequence(np.random.default_rng(3), 600, 8, spread=30.0)
    ours, theirs = evaluate(gt, tracks), ref.evaluate(gt, tracks)
    for key, value in theirs.items():
        assert ours[key] == pytest.approx(value, abs=1e-9), key
    m = EpisodeMetrics()
    for k, ((gi, gb), (ti, tb)) in enumerate(zip(gt, tracks)):
        m.update(gi, gb, ti, tb)
        assert m.frame_gospa() == gospa(gb, tb, 50.0, 1.0)
    for k in (0, 255, 256, 300, 599, 550, -1):
        assert m.frame_gospa(k) == gospa(gt[k][1], tracks[k][1], 50.0, 1.0)


def test_a_long_episode_keeps_little_per_frame():
    """Only the nonzero similarities are kept: 200 objects a frame cost under 20 KB (a dense matrix alone: 320 KB),
    and the summary's peak stays within a small factor of that."""
    rng = np.random.default_rng(0)
    frames = [(np.arange(200), np.c_[rng.uniform(0, 600, (200, 2)), np.full((200, 2), 24.0)]) for _ in range(20)]
    m = EpisodeMetrics()
    tracemalloc.start()
    before = tracemalloc.get_traced_memory()[0]
    for k in range(300):
        ids, boxes = frames[k % 20]
        m.update(ids, boxes, ids, boxes + rng.normal(0, 2, boxes.shape))
    stored = tracemalloc.get_traced_memory()[0] - before
    tracemalloc.reset_peak()
    m.summary()
    peak = tracemalloc.get_traced_memory()[1] - before
    tracemalloc.stop()
    assert stored / 300 < 20 * 1024 and peak < 4 * stored, (stored / 300, peak / stored)


def occlusion_episode(visibility, reported, shift=(3.0, 4.0), frames_after=0):
    """One target (id 1) at a fixed box; visibility per frame; `reported[k]` the id of the track reported on it in
    frame k (None: no track). A track's box is the target's while it is at least half visible (so it is matched),
    shifted by `shift` while it is hidden (unmatched: the estimate carried through)."""
    m = EpisodeMetrics()
    box = np.array([[100.0, 100.0, 20.0, 40.0]])
    for v, t in zip(visibility + [1.0] * frames_after, reported + [None] * frames_after):
        trk_ids = np.array([] if t is None else [t])
        trk_boxes = np.zeros((0, 4)) if t is None else box + ([*shift, 0, 0] if v < 0.05 else 0)
        scored = v >= 0.05
        m.update(np.array([1] if scored else []), box if scored else np.zeros((0, 4)), trk_ids, trk_boxes,
                 everyone=(np.array([1]), box, np.array([v])))
    return m.summary(), m.per_target()


def test_occlusion_windows_on_hand_made_sequences():
    hidden = [1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.3, 1.0]        # held by track 7, hidden 4 frames, revealed in frame 7
    s, per = occlusion_episode(hidden, [7, 7, 7, 7, None, 7, 7, 7], frames_after=19)   # its window: frames 7-26
    assert s["HiddenCentreError"] == 5.0 and s["Reacquired"] == 1.0 and s["Occlusions"] == 1   # 3 hidden frames held
    assert per[1]["HiddenCentreError"] == 5.0 and per[1]["Reacquired"] == 1.0
    s, _ = occlusion_episode(hidden, [7, 7, 7, 7, None, 7, 7, 7], frames_after=18)   # the episode cuts the window
    assert s["Occlusions"] == 0 and s["Reacquired"] is None and s["HiddenCentreError"] == 5.0
    s, _ = occlusion_episode(hidden, [7, 7, 7, 7, 7, 7, 9, 9], frames_after=25)    # another track takes it back
    assert s["Reacquired"] == 0.0 and s["Occlusions"] == 1
    s, _ = occlusion_episode(hidden[:6] + [1.0] * 30, [7] * 6 + [9] * 10 + [7] * 20)  # track 7 back 10 frames later
    assert s["Reacquired"] == 1.0
    s, _ = occlusion_episode(hidden[:6] + [1.0] * 30, [7] * 6 + [9] * 20 + [7] * 10)  # 20 frames later: too late
    assert s["Reacquired"] == 0.0 and s["Occlusions"] == 1
    s, _ = occlusion_episode([0.0, 0.0, 1.0, 1.0], [None, None, 7, 7], frames_after=30)  # hidden before any match
    assert s["Occlusions"] == 0 and s["HiddenCentreError"] is None
    s, _ = occlusion_episode([1.0] + [0.0] * 30, [7] + [None] * 30)                 # never revealed: not decided
    assert s["Occlusions"] == 0 and s["HiddenCentreError"] is None             # and the holder reported nothing
    plain = EpisodeMetrics()
    plain.update([1], [[0, 0, 10, 10]], [1], [[0, 0, 10, 10]])
    assert plain.summary()["Occlusions"] == 0 and plain.summary()["Reacquired"] is None


def test_occlusion_windows_need_every_scored_target_among_those_in_view():
    m = EpisodeMetrics()
    box = np.array([[0.0, 0.0, 10.0, 10.0]])
    with pytest.raises(ValueError, match=r"frame 0: everyone must include every scored ground-truth id; missing \[1\]"):
        m.update([1], box, [5], box, everyone=(np.array([2]), box, np.array([1.0])))
    with pytest.raises(ValueError, match=r"frame 0: everyone's visibility must be \(1,\) finite numbers"):
        m.update([1], box, [5], box, everyone=(np.array([1]), box, np.array([np.nan])))
    with pytest.raises(ValueError, match=r"frame 0: everyone must be \(ids, boxes, visibility\)"):
        m.update([1], box, [5], box, everyone=(np.array([1]), box))
    assert len(m) == 0 and m.summary()["TP"] == 0   # a rejected frame is not scored


def test_every_family_reports_the_fields_it_declares_in_their_order_and_types():
    m = EpisodeMetrics()
    boxes = np.array([[0.0, 0, 10, 10], [20, 0, 10, 10]])
    for _ in range(3):
        m.update(np.array([1, 2]), boxes, np.array([5]), boxes[:1] + 1, (np.array([1, 2]), boxes, np.array([1.0, 0.0])))
    for family in m.families:
        values = family.summary()
        assert tuple(values) == tuple(f.name for f in family.FIELDS), type(family).__name__
        assert all(f.value(values[f.name]) == values[f.name] for f in family.FIELDS)
    summary = m.summary()
    assert tuple(summary) == METRICS and all(type(summary[f.name]) is f.kind for f in SUMMARY_FIELDS
                                             if summary[f.name] is not None)
    assert sorted(m.per_target()[1]) == list(PER_TARGET)


"""OC-SORT on hand-made detections: what each observation-centric part does, and many tracks at once as each alone.
Box for box against the official code on real sequences: `mtt-sim check-real` (tests/test_cli.py runs it on data)."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mtt_sim import trackers
from mtt_sim.trackers.parts.kalman import box_model

W, H = 40.0, 100.0


def obs(*rows):
    """An observation of detections (x, y, w, h, confidence)."""
    dets = np.array(rows, float).reshape(-1, 5)
    return {"detections": dets, "num_detections": np.int64(len(dets))}


def run(spec, frames):
    """{frame: {id: box}} of a tracker fed `frames`, a list of lists of detection rows."""
    t = trackers.make(spec)
    t.reset({"image_size": (1920, 1080)})
    out = {}
    for k, rows in enumerate(frames):
        tracks = t.update(obs(*rows))
        out[k] = {int(i): b for i, b in zip(tracks.ids, tracks.boxes)}
    return out


def walker(xs, y=200.0, conf=0.9):
    """One person's detections at the x positions given (None: missed that frame)."""
    return [[] if x is None else [[x, y, W, H, conf]] for x in xs]


def test_reported_boxes_are_the_detections_themselves():
    frames = walker([100.0, 103.0, 109.0, 112.5, 118.0, 121.0])
    out = run("ocsort", frames)
    assert [list(o) for o in out.values()] == [[1]] * 6  # the first min_hits frames at once, then by streak
    for k in range(1, 6):
        np.testing.assert_array_equal(out[k][1], frames[k][0][:4])
    np.testing.assert_allclose(out[0][1], frames[0][0][:4], atol=1e-5)  # a newborn's box: its filter's state


def test_a_track_survives_max_age_missed_frames_and_no_more():
    xs = [100.0 + 5 * k for k in range(6)]
    gap = lambda n: walker(xs + [None] * n + [100.0 + 5 * (6 + n)])
    assert list(run("ocsort:max_age=4", gap(4))[10]) == []  # found again, but its streak starts anew
    assert list(run("ocsort:max_age=4,min_hits=0", gap(4))[10]) == [1]
    assert list(run("ocsort:max_age=4,min_hits=0", gap(5))[11]) == [2]


def test_recovery_matches_a_stopped_person_by_the_last_observation():
    """Running at 20 px a frame, then missed twice while stopping: the prediction has run on beyond any overlap,
    the last observation has not, so OCR keeps the id where SORT (prediction only) starts a new one."""
    frames = walker([0.0, 20.0, 40.0, 60.0, 80.0, 100.0, None, None, 104.0, 104.0])
    assert list(run("ocsort:min_hits=0", frames)[8]) == [1]
    assert list(run("sort:min_hits=0,max_age=30", frames)[8]) == [2]


def test_re_update_rewinds_to_the_first_miss_and_runs_the_filter_along_the_gap():
    """Standing still, missed 10 frames, found 33 px on: the filter is set back to its state at the first missed
    frame and updated with a box every 3 px of the straight path (predicting between), then with the detection,
    here computed step by step with the textbook Kalman equations."""
    box = lambda x: [[x, 200.0, 100.0, 100.0, 0.9]]
    t = trackers.make("ocsort:min_hits=0")
    t.reset({})
    for _ in range(10):
        t.update(obs(*box(100.0)))
    t.update(obs())
    first_miss = t.tracks.kf.x.copy(), t.tracks.kf.P.copy()
    for _ in range(9):
        t.update(obs())
    t.update(obs(*box(133.0)))

    m = box_model()
    x, P = first_miss[0][0], first_miss[1][0]
    z_last = np.array([150.0, 250.0, 100.0 * 100.0, 100.0 / (100.0 + 1e-6)])
    z_new = np.array([183.0, 250.0, 100.0 * 100.0, 100.0 / (100.0 + 1e-6)])
    w_last, w_new = np.sqrt(z_last[2] * z_last[3]), np.sqrt(z_new[2] * z_new[3])
    h_last, h_new = np.sqrt(z_last[2] / z_last[3]), np.sqrt(z_new[2] / z_new[3])

    def kalman_update(x, P, z):
        S = m.H @ P @ m.H.T + m.R
        K = P @ m.H.T @ np.linalg.inv(S)
        return x + K @ (z - m.H @ x), (np.eye(7) - K @ m.H) @ P

    for i in range(1, 12):  # the 10 missed frames and the one found
        w, h = w_last + i * (w_new - w_last) / 11, h_last + i * (h_new - h_last) / 11
        x, P = kalman_update(x, P, np.array([150.0 + i * 3.0, 250.0, w * h, w / h]))
        if i < 11:
            x, P = m.F @ x, m.F @ P @ m.F.T + m.Q
    x, P = kalman_update(x, P, z_new)
    np.testing.assert_allclose(t.tracks.kf.x[0], x, rtol=1e-9)
    np.testing.assert_allclose(t.tracks.kf.P[0], P, rtol=1e-6, atol=1e-9)


def test_momentum_prefers_the_detection_along_the_track_s_direction():
    """A person walking right at 10 px a frame; two detections near the prediction: 14 px below it (IoU 0.754) and
    6 px ahead of it (IoU 0.739). IoU alone takes the one below; with the direction term the one ahead."""
    frames = walker([100.0 + 10 * k for k in range(8)])
    frames.append([[180.0, 214.0, W, H, 0.9], [186.0, 200.0, W, H, 0.9]])
    assert run("ocsort:min_hits=0", frames)[8][1].tolist() == [186.0, 200.0, W, H]
    assert run("ocsort:min_hits=0,inertia=0", frames)[8][1].tolist() == [180.0, 214.0, W, H]


def test_a_detection_at_det_thresh_is_not_used():
    assert run("ocsort:min_hits=0", walker([100.0, 105.0], conf=0.6)) == {0: {}, 1: {}}
    assert run("ocsort:min_hits=0", walker([100.0, 105.0], conf=0.61))[1].keys() == {1}


def test_byte_round_keeps_a_track_through_low_confidence_detections_only_when_asked():
    frames = walker([100.0, 104.0, 108.0, 112.0]) + walker([116.0, 120.0], conf=0.3)
    assert list(run("ocsort:min_hits=0", frames)[5]) == []
    assert list(run("ocsort:min_hits=0,use_byte=true", frames)[5]) == [1]


@settings(max_examples=25, deadline=None)
@given(st.lists(st.tuples(st.floats(-8, 8), st.floats(-4, 4), st.lists(st.booleans(), min_size=30, max_size=30)),
                min_size=2, max_size=5))
def test_many_people_at_once_are_tracked_as_each_alone(people):
    """People far apart never interact: each one's boxes, frame by frame, are those of a run on it alone; so the
    vectorised bookkeeping (recovery, re-update, deletion) never mixes rows."""
    lanes = [[[] if not seen else [[300.0 * i + 100 + vx * k, 300.0 + vy * k, W, H, 0.9]]
              for k, seen in enumerate(seen_at)] for i, (vx, vy, seen_at) in enumerate(people)]
    together = run("ocsort:max_age=5", [sum(rows, []) for rows in zip(*lanes)])
    alone = [run("ocsort:max_age=5", lane) for lane in lanes]
    for k in range(30):
        got = sorted(map(tuple, np.round(list(together[k].values()), 6)))
        want = sorted(tuple(np.round(b, 6)) for a in alone for b in a[k].values())
        assert got == want, k

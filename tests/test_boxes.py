"""Box geometry: hand-made boxes with known answers, the matching's optimum and threshold edge, the frame check."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

import trackeval_reference as ref
from mtt_sim.boxes import (EPS, box_iou, centre_distance, centres, check_frame, match, overlap, pair_iou, rows_of,
                           union_boxes)

SQUARE = [0.0, 0.0, 10.0, 10.0]


def test_iou_of_hand_made_boxes():
    others = [[5, 0, 10, 10], [2, 2, 5, 5], [10, 0, 10, 10], [20, 20, 5, 5], SQUARE]
    np.testing.assert_allclose(box_iou([SQUARE], others), [[50 / 150, 25 / 100, 0.0, 0.0, 1.0]])
    assert box_iou([SQUARE], np.zeros((0, 4))).shape == (1, 0)


def test_a_box_without_area_overlaps_nothing():
    flat = [0.0, 0.0, 0.0, 10.0]  # TrackEval's guard: 0, not 0 / 0
    assert box_iou([flat], [flat, SQUARE]).tolist() == [[0.0, 0.0]]
    assert pair_iou(np.array([flat]), np.array([flat])).tolist() == [0.0]


def test_pair_iou_is_row_wise_broadcasting_and_keeps_float32_areas():
    a = np.array([SQUARE, SQUARE])
    b = np.array([[5, 0, 10, 10], [0, 5, 10, 10.0]])
    np.testing.assert_allclose(pair_iou(a, b), [1 / 3, 1 / 3])
    moved = np.stack([b, b[::-1], a])  # (3, 2, 4) against (2, 4)
    np.testing.assert_allclose(pair_iou(a, moved), [[1 / 3, 1 / 3]] * 2 + [[1.0, 1.0]])
    inter, area, _ = overlap(a.astype(np.float32), b)
    assert area.dtype == np.float32 and inter.tolist() == [50.0, 50.0]


@given(st.lists(st.tuples(*[st.floats(0, 50)] * 2, *[st.floats(0.1, 20)] * 2), min_size=1, max_size=6),
       st.lists(st.tuples(*[st.floats(0, 50)] * 2, *[st.floats(0.1, 20)] * 2), min_size=1, max_size=6))
def test_iou_matches_trackevals_plain_loop(a, b):
    np.testing.assert_allclose(box_iou(np.array(a), np.array(b)), ref.iou(a, b), atol=1e-12)


boxes = arrays(float, st.tuples(st.integers(0, 6), st.just(4)),
               elements=st.floats(0.0, 100.0, allow_nan=False, allow_infinity=False))


@given(boxes, st.data())
def test_all_pairs_iou_equals_the_row_wise_iou_on_its_diagonal(a, data):
    b = data.draw(arrays(float, a.shape, elements=st.floats(0.0, 100.0)))
    np.testing.assert_array_equal(np.diagonal(box_iou(a, b)), pair_iou(a, b))


def test_union_of_each_group():
    b = np.array([[0, 0, 1, 1], [5, 5, 1, 1], [2, 3, 4, 1], [10, 10, 2, 2.0]])
    assert union_boxes(b, np.array([0, 0, 1, 2]), 3).tolist() == [[0, 0, 6, 6], [2, 3, 4, 1], [10, 10, 2, 2]]


def test_centres_and_their_distances():
    a, b = np.array([[0, 0, 2, 2.0]]), np.array([[3, 4, 2, 2.0], [0, 0, 2, 2.0]])
    assert centres(b).tolist() == [[4, 5], [1, 1]]
    assert centre_distance(a, b).tolist() == [[5.0, 0.0]]


def test_rows_of_ids():
    assert rows_of(np.array([7, 3, 9]), np.array([9, 4, 7, 3])).tolist() == [2, -1, 0, 1]
    assert rows_of(np.zeros(0, int), np.array([1, 2])).tolist() == [-1, -1]


def test_match_finds_the_optimum_not_the_greedy_pairs():
    sim = np.array([[0.9, 0.8], [0.8, 0.0]])  # greedy takes 0.9 and is left with nothing; the optimum makes 1.6
    rows, cols = match(sim, 0.5)
    assert rows.tolist() == [0, 1] and cols.tolist() == [1, 0]


def test_match_threshold_is_inclusive_and_exact():
    below = np.nextafter(0.5, 0.0)
    assert [len(match(np.array([[s]]), 0.5)[0]) for s in (0.5, below)] == [1, 0]
    assert len(match(np.array([[below]]), 0.5 - EPS)[0]) == 1  # TrackEval's `>= 0.5`
    assert len(match(np.zeros((0, 3)), 0.5)[0]) == 0


def test_match_bonus_keeps_a_pair_but_never_one_below_the_threshold():
    sim = np.array([[0.6, 0.9], [0.2, 0.0]])
    bonus = np.array([[1000.0, 0.0], [1000.0, 0.0]])
    rows, cols = match(sim, 0.5, bonus)
    assert rows.tolist() == [0] and cols.tolist() == [0]
    assert sim.tolist() == [[0.6, 0.9], [0.2, 0.0]]  # the caller's similarities are left as they were


def test_check_frame_passes_good_frames_and_names_the_problem():
    ids, b = check_frame("tracks", [4, 2], [SQUARE, [1, 1, 2, 2]], "frame 3", positive=True)
    assert ids.dtype == np.int64 and b.dtype == np.float64 and b.shape == (2, 4)
    ids, b = check_frame("tracks", [], [], "frame 3")
    assert ids.shape == (0,) and b.shape == (0, 4)
    with pytest.raises(ValueError, match=r"^frame 3: tracks boxes must be finite; row 1 is not$"):
        check_frame("tracks", [1, 2], [SQUARE, [0, 0, np.nan, 1]], "frame 3")
    with pytest.raises(ValueError, match=r"^frame 3: tracks boxes must have a positive width and height; row 0 does not$"):
        check_frame("tracks", [1], [[0, 0, 0, 1]], "frame 3", positive=True)
    assert check_frame("tracks", [1], [[0, 0, 0, 1]], "frame 3")[1].tolist() == [[0, 0, 0, 1]]
    with pytest.raises(ValueError, match=r"gt ids must have shape \(n,\) and boxes \(n, 4\), got \(2,\) and \(1, 4\)"):
        check_frame("gt", [1, 2], [SQUARE], "frame 0")
    with pytest.raises(ValueError, match=r"gt ids must be integers, got dtype float64"):
        check_frame("gt", [1.5], [SQUARE], "frame 0")
    with pytest.raises(ValueError, match=r"gt ids must be unique within a frame"):
        check_frame("gt", [1, 1], [SQUARE, SQUARE], "frame 0")

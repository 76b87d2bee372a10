"""Ground truth from the label map: visible fractions, visible boxes and pieces with known answers."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from helpers import placed, still, tiny
from mtt_sim.boxes import clip_boxes, overlapping_pairs


def test_unoccluded_target_is_fully_visible_with_its_exact_box():
    env = placed(tiny([still(shape="rect")]), [[100.0, 50.0]])
    t = env.truth
    assert t.visibility.tolist() == [1.0]
    np.testing.assert_allclose(t.boxes[0], [80, 30, 40, 40])
    np.testing.assert_allclose(t.visible_boxes[0], [80, 30, 40, 40])
    assert len(t.pieces) == 0


def test_half_behind_an_occluder_is_half_visible():
    occluder = {"rect": [60.0, 0.0, 40.0, 100.0]}  # covers x < 100: the target's left half
    for shape in ("rect", "ellipse"):
        env = placed(tiny([still(shape=shape)], occluders=[occluder]), [[100.0, 50.0]])
        assert abs(env.truth.visibility[0] - 0.5) < 0.03, shape
        x, y, w, h = env.truth.visible_boxes[0]
        assert x == 100 and abs(w - 20) <= 1 and abs(h - 40) <= 1


def test_an_occluder_cutting_a_target_leaves_two_pieces():
    pole = {"rect": [98.0, 0.0, 4.0, 100.0]}
    env = placed(tiny([still(shape="rect")], occluders=[pole]), [[100.0, 50.0]])
    pieces = env.truth.pieces
    assert len(pieces) == 2 and set(pieces[:, 0]) == {0}
    np.testing.assert_allclose(sorted(pieces[:, 1].tolist()), [80, 102])
    assert abs(env.truth.visibility[0] - 36 / 40) < 0.01


def test_target_leaving_the_image_is_clipped_and_drops_out_when_gone():
    env = placed(tiny([still(shape="rect")]), [[190.0, 50.0]])
    np.testing.assert_allclose(env.truth.boxes[0], [170, 30, 30, 40])
    assert env.truth.visibility[0] == 1.0
    env.source.world.place([[400.0, 50.0]])
    env.observe()
    assert len(env.truth) == 0


def test_higher_layer_hides_lower_layer_in_topdown():
    groups = [still(name="low", layer=0, shape="rect"), still(name="high", layer=1, shape="rect")]
    env = placed(tiny(groups), [[100.0, 50.0], [100.0, 50.0]])
    vis = dict(zip(env.truth.ids.tolist(), env.truth.visibility.tolist()))
    assert vis == {1: 0.0, 2: 1.0}


def test_standing_nearer_target_occludes_farther():
    groups = [still(name="far", size=(20.0, 40.0)), still(name="near", size=(20.0, 40.0))]
    sc = tiny(groups, world={"projection": "standing", "far_scale": 1.0})
    env = placed(sc, [[100.0, 60.0], [100.0, 70.0]])  # feet at y=60 (far) and y=70 (near)
    vis = dict(zip(env.truth.ids.tolist(), env.truth.visibility.tolist()))
    assert vis[2] == 1.0 and 0.2 < vis[1] < 0.35  # 10 of the far one's 40 rows stick out above


boxes = st.lists(st.tuples(st.floats(0, 100), st.floats(0, 100), st.floats(0.5, 30), st.floats(0.5, 30)), max_size=30)


@settings(max_examples=200, deadline=None)
@given(boxes, st.sampled_from([0.0, 1.0]))
def test_overlapping_pairs_matches_brute_force(rows, margin):
    b = np.array(rows, float).reshape(-1, 4)
    want = {(i, j) for i in range(len(b)) for j in range(i + 1, len(b))
            if b[i, 0] < b[j, 0] + b[j, 2] + margin and b[j, 0] < b[i, 0] + b[i, 2] + margin
            and b[i, 1] < b[j, 1] + b[j, 3] + margin and b[j, 1] < b[i, 1] + b[i, 3] + margin}
    i, j = overlapping_pairs(b, margin)
    assert {(min(a, c), max(a, c)) for a, c in zip(i.tolist(), j.tolist())} == want
    assert len(i) == len(want)


@given(boxes)
def test_clipped_boxes_lie_inside_the_image(rows):
    b = np.array(rows, float).reshape(-1, 4) * 3 - (150, 150, 0, 0)  # positions anywhere, sizes positive
    c = clip_boxes(b, 200, 100)
    assert (c >= 0).all() and (c[:, 0] + c[:, 2] <= 200).all() and (c[:, 1] + c[:, 3] <= 100).all()


def test_pieces_labelled_within_the_visible_box_are_those_of_the_whole_region():
    """`pieces_of` labels only the visible pixels' bounding box; the whole region's labels (the brute force) give the
    same pieces in the same order, for regions cut at random by ellipses and rectangles."""
    import cv2

    from mtt_sim.sim.truth import pieces_of

    # by hand: a piece starting on row 5 at the right, another on row 6 at the left. Raster order (and OpenCV's 2x2
    # blocks from row 4) finds the right one first; blocks from row 5 would pair rows 5 and 6 and find the left first
    mask = np.zeros((20, 20), np.uint8)
    mask[5:9, 12:16] = mask[6:10, 2:6] = 255
    np.testing.assert_array_equal(pieces_of(mask, 32, cv2.boundingRect(mask)), [[12, 5, 4, 4], [2, 6, 4, 4]])
    rng, compared = np.random.default_rng(0), 0
    for _ in range(400):
        h, w = (int(v) for v in rng.integers(8, 300, 2))
        mask = np.zeros((h, w), np.uint8)
        for _ in range(rng.integers(1, 6)):
            centre = (int(rng.integers(0, w)), int(rng.integers(0, h)))
            cv2.ellipse(mask, centre, (int(rng.integers(1, 40)), int(rng.integers(1, 80))), 0, 0, 360, 255, -1)
        for _ in range(rng.integers(0, 5)):
            x, y = int(rng.integers(0, w)), int(rng.integers(0, h))
            cv2.rectangle(mask, (x, y), (x + int(rng.integers(1, 40)), y + int(rng.integers(1, 60))), 0, -1)
        seen = cv2.countNonZero(mask)
        if not seen:
            continue
        count, _, stats, _ = cv2.connectedComponentsWithStats(mask, connectivity=8)
        big = stats[1:, cv2.CC_STAT_AREA] >= max(4, 0.05 * seen)
        whole = stats[1:][big][:, :4] if count > 2 and big.sum() >= 2 else np.zeros((0, 4), np.int32)
        np.testing.assert_array_equal(pieces_of(mask, seen, cv2.boundingRect(mask)), whole)
        compared += len(whole) >= 2
    assert compared > 50  # many regions did fall into pieces

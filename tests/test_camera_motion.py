"""Camera-motion compensation: the estimators find a known shift, the warps move states as geometry says, and SORT,
ByteTrack and LMB with it get back what a shaking camera costs them."""

import numpy as np
import pytest

from mtt_sim import trackers
from mtt_sim.lab.experiment import run_episode
from mtt_sim.trackers.parts.camera_motion import IDENTITY, CameraMotion, warp_boxes, warp_centres


def textured(seed=0, size=(240, 320)):
    """A smooth random texture (RGB uint8): blobs about 6 px across, so a gradient method converges from a shift of
    a few pixels (ECC does not from raw pixel noise)."""
    import cv2

    noise = np.random.default_rng(seed).integers(0, 255, (*size, 3), dtype=np.uint8)
    return cv2.GaussianBlur(noise, (0, 0), 3)


@pytest.mark.parametrize("method", ["sparse_flow", "ecc"])
def test_estimators_find_a_known_shift(method):
    """The view moves 6 px left and 4 px down between two frames: a point of the first is at (x - 6, y + 4)."""
    world = textured(size=(300, 400))
    first, second = world[20:260, 20:340], world[16:256, 26:346]
    camera = CameraMotion(method)
    assert np.array_equal(camera.estimate(first), IDENTITY)  # the first frame: nothing to compare with
    np.testing.assert_allclose(camera.estimate(second), [[1, 0, -6], [0, 1, 4]], atol=0.3)


def test_no_compensation_is_the_identity_and_a_bad_method_is_named():
    assert np.array_equal(CameraMotion("none").estimate(None), IDENTITY)
    with pytest.raises(ValueError, match=r"cmc='flow': allowed: 'none', 'ecc', 'sparse_flow'"):
        CameraMotion("flow")
    with pytest.raises(ValueError, match=r"parameter cmc='flow': allowed: 'none', 'ecc', 'sparse_flow'"):
        trackers.make("sort:cmc=flow")


def test_warps_move_centres_and_scale_sizes():
    double = np.array([[2.0, 0.0, 1.0], [0.0, 2.0, -1.0]])  # twice the size, then shifted
    np.testing.assert_allclose(warp_boxes(np.array([[10.0, 10.0, 4.0, 6.0]]), double), [[21.0, 19.0, 8.0, 12.0]])
    lmb_state = np.array([[10.0, 10.0, 4.0, 6.0, 1.0, -1.0, 0.5, 0.0]])
    moved, P = warp_centres(lmb_state, np.eye(8)[None], double, "corner_size")
    np.testing.assert_allclose(moved, [[21.0, 19.0, 8.0, 12.0, 2.0, -2.0, 1.0, 0.0]])
    assert P[0, 0, 0] == pytest.approx(4.0) and P[0, 0, 2] == 0.0 and P[0, 2, 2] == pytest.approx(4.0)
    sort_state = np.array([[12.0, 13.0, 24.0, 4 / 6, 1.0, -1.0, 2.0]])
    moved, P = warp_centres(sort_state, np.eye(7)[None], double, "centre_area")
    np.testing.assert_allclose(moved, [[25.0, 25.0, 96.0, 4 / 6, 2.0, -2.0, 8.0]])
    assert P[0, 2, 2] == pytest.approx(16.0) and P[0, 3, 3] == 1.0
    bytetrack_state = np.array([[12.0, 13.0, 0.5, 6.0, 1.0, -1.0, 0.01, 0.5]])
    moved, P = warp_centres(bytetrack_state, np.eye(8)[None], double, "centre_aspect_height")
    np.testing.assert_allclose(moved, [[25.0, 25.0, 0.5, 12.0, 2.0, -2.0, 0.01, 1.0]])
    assert P[0, 2, 2] == 1.0 and P[0, 3, 3] == pytest.approx(4.0)
    same = warp_centres(sort_state, np.eye(7)[None], IDENTITY, "centre_area")
    assert same[0] is sort_state


def test_compensation_gets_back_what_a_shaking_camera_costs_sort_bytetrack_and_lmb():
    shaking = {"render.camera": "shake", "render.shake": 8.0, "env.max_steps": 80}
    for spec, compensated_spec in (("sort", "sort:cmc=sparse_flow"), ("bytetrack", "bytetrack:cmc=ecc"),
                                   ("lmb:reid=false", "lmb:reid=false,cmc=sparse_flow")):
        plain = run_episode("mot17_like", spec, seed=3, config=shaking)["metrics"]["MOTA"]
        compensated = run_episode("mot17_like", compensated_spec, seed=3, config=shaking)["metrics"]["MOTA"]
        assert compensated > plain + 0.05, (spec, plain, compensated)
    assert trackers.make("sort:cmc=ecc").needs_frame and not trackers.make("sort").needs_frame

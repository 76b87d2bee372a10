"""Appearance features: hand-computed histograms and coefficients, the descriptor on a known edge."""

import numpy as np
import pytest

from mtt_sim.trackers.parts.appearance import (bhattacharyya, gradient_descriptors, histograms, hs_bins, orientation_maps,
                                 rgb_bins)


def test_rgb_histogram_of_a_hand_made_region():
    frame = np.zeros((10, 10, 3), np.uint8)
    frame[:, :5] = (255, 0, 0)    # left half red: bin 15 * 256
    frame[:, 5:] = (0, 0, 17)     # right half: blue level 1, bin 1
    bins = rgb_bins(frame)
    assert bins[0, 0] == 15 * 256 and bins[0, 9] == 1
    h = histograms(bins, 4096, np.array([[5.0, 5.0], [2.0, 5.0]]), (4, 4))
    assert h[0, 15 * 256] == pytest.approx(0.5) and h[0, 1] == pytest.approx(0.5)  # columns 3..6: half and half
    assert h[1, 15 * 256] == pytest.approx(1.0)                                     # columns 0..3: all red
    np.testing.assert_allclose(h.sum(axis=1), 1.0)


def test_regions_partly_outside_count_only_inside_pixels_and_wholly_outside_give_zeros():
    bins = np.zeros((10, 10), np.int64)
    h = histograms(bins, 2, np.array([[0.0, 0.0], [-50.0, -50.0]]), (4, 4))
    assert h[0].tolist() == [1.0, 0.0] and h[1].tolist() == [0.0, 0.0]


def test_hs_bins_separate_hues():
    frame = np.zeros((1, 2, 3), np.uint8)
    frame[0, 0], frame[0, 1] = (255, 0, 0), (0, 0, 255)
    b = hs_bins(frame)
    assert b[0, 0] != b[0, 1] and b.max() < 64


def test_bhattacharyya_values():
    q = np.array([0.5, 0.5, 0.0])
    p = np.array([[0.5, 0.5, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])
    np.testing.assert_allclose(bhattacharyya(p, q), [1.0, 0.0, np.sqrt(0.5)])
    both = np.stack([q, [0.0, 0.0, 1.0]])  # against several templates at once: one column each
    np.testing.assert_allclose(bhattacharyya(p, both), [[1.0, 0.0], [0.0, 1.0], [np.sqrt(0.5), 0.0]])


@pytest.mark.parametrize("edge, dominant", [("vertical", 0), ("horizontal", 2)])
def test_descriptor_on_an_edge_has_the_known_dominant_orientation(edge, dominant):
    frame = np.zeros((40, 40, 3), np.uint8)
    if edge == "vertical":
        frame[:, 20:] = 255    # dark to bright along +x: gradient angle 0
    else:
        frame[20:, :] = 255    # dark to bright along +y (down): gradient angle 90 deg, bin 2 of 8
    orient, mag = orientation_maps(frame)
    d = gradient_descriptors(orient, mag, np.array([[20.0, 20.0]]), (16, 16))
    per_orientation = d.reshape(16, 8).sum(axis=0)
    assert int(np.argmax(per_orientation)) == dominant
    assert per_orientation[dominant] > 0.99 * per_orientation.sum()
    assert np.linalg.norm(d) == pytest.approx(1.0)

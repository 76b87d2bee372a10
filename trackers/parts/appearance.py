"""Appearance features of image regions, for many regions at once: colour histograms, the gradient-orientation
descriptor, Bhattacharyya coefficients.

Each feature is computed on a per-frame map (bin index, or orientation bin and weight, per pixel) and then
gathered for every region of one size at once: region pixels are addressed by broadcasting offsets, and all
histograms come from one `np.bincount`, so evaluating every particle of a frame has no per-particle loop.
Pixels of a region that fall outside the image count in no bin.
"""

from __future__ import annotations

import cv2
import numpy as np


def rgb_bins(frame: np.ndarray, levels: int = 16) -> np.ndarray:
    """Per-pixel bin of an RGB frame quantised to `levels` per channel (levels**3 bins)."""
    q = (frame.astype(np.int32) * levels) >> 8
    return (q[..., 0] * levels + q[..., 1]) * levels + q[..., 2]


def hs_bins(frame: np.ndarray, h_levels: int = 8, s_levels: int = 8) -> np.ndarray:
    """Per-pixel bin of the hue-saturation plane of an RGB frame (h_levels * s_levels bins)."""
    hsv = cv2.cvtColor(frame, cv2.COLOR_RGB2HSV)
    h = (hsv[..., 0].astype(np.int32) * h_levels) // 180
    s = (hsv[..., 1].astype(np.int32) * s_levels) >> 8
    return h * s_levels + s


def _region_pixels(centres: np.ndarray, size: tuple[int, int], shape: tuple[int, int], stride: int = 1):
    """Flat image index of every `stride`-th pixel (rows and columns) of every w x h region (n, h', w'), and
    whether it lies inside the image (None when every region lies wholly inside: then one region's offsets plus
    each region's corner are the indices, two passes over the pixels instead of eight)."""
    w, h = size
    x0 = np.round(centres[:, 0] - w / 2).astype(np.intp)
    y0 = np.round(centres[:, 1] - h / 2).astype(np.intp)
    dy, dx = np.arange(0, h, stride), np.arange(0, w, stride)
    if len(x0) and x0.min() >= 0 and y0.min() >= 0 and x0.max() + dx[-1] < shape[1] and y0.max() + dy[-1] < shape[0]:
        offsets = dy[:, None] * shape[1] + dx[None, :]
        return (y0 * shape[1] + x0)[:, None, None] + offsets[None], None
    rows = y0[:, None, None] + dy[None, :, None]  # (n, h', 1)
    cols = x0[:, None, None] + dx[None, None, :]  # (n, 1, w')
    inside = ((rows >= 0) & (rows < shape[0])) & ((cols >= 0) & (cols < shape[1]))
    flat = np.clip(rows, 0, shape[0] - 1) * shape[1] + np.clip(cols, 0, shape[1] - 1)
    return flat, inside


def _binned(per_pixel_bin: np.ndarray, n_bins: int, flat: np.ndarray, inside: np.ndarray | None,
            weights: np.ndarray | None) -> np.ndarray:
    """Histograms (n, n_bins): region pixels outside the image (inside False) go to a sentinel bin that is dropped."""
    n = len(flat)
    b = per_pixel_bin if inside is None else np.where(inside, per_pixel_bin, n_bins)
    index = (b + (np.arange(n) * (n_bins + 1))[:, None, None]).ravel()
    w = None if weights is None else np.broadcast_to(weights, b.shape).ravel()
    return np.bincount(index, weights=w, minlength=n * (n_bins + 1)).reshape(n, n_bins + 1)[:, :n_bins]


def histograms(bins: np.ndarray, n_bins: int, centres: np.ndarray, size: tuple[int, int],
               weights: np.ndarray | None = None, stride: int = 1) -> np.ndarray:
    """Normalised histograms (n, n_bins) of `bins` over the w x h regions centred at `centres` (n, 2).

    `weights` (sampled rows, sampled columns) weighs each region pixel (a kernel); `stride` samples every
    stride-th row and column (a regular sample of a large region); regions wholly outside the image give zeros.
    """
    flat, inside = _region_pixels(np.asarray(centres, float).reshape(-1, 2), size, bins.shape, stride)
    hist = _binned(bins.ravel().take(flat), n_bins, flat, inside, weights)
    if inside is None:
        inside = np.ones((1,) + flat.shape[1:], bool)
    total = (inside * (1.0 if weights is None else weights[None])).sum(axis=(1, 2))
    return hist / np.where(total > 0, total, 1.0)[:, None]


def bhattacharyya(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Bhattacharyya coefficient rho = sum sqrt(p q) of each row of p (n, B) with q (B,) (eq. 4 of Li et al. 2007),
    or with every row of q (k, B) at once, (n, k). For one q only its nonzero bins can contribute, so only they
    are read."""
    q = np.asarray(q)
    if q.ndim == 2:
        return np.sqrt(np.asarray(p)) @ np.sqrt(q).T
    nz = np.flatnonzero(q)
    return np.sqrt(np.asarray(p)[:, nz] * q[nz][None]).sum(axis=1)


def orientation_maps(frame: np.ndarray, n_orient: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """Per-pixel gradient orientation bin (0..n_orient-1) and gradient magnitude of the frame's grey levels."""
    grey = cv2.cvtColor(frame, cv2.COLOR_RGB2GRAY).astype(np.float32)
    gx = cv2.Sobel(grey, cv2.CV_32F, 1, 0, ksize=3)
    gy = cv2.Sobel(grey, cv2.CV_32F, 0, 1, ksize=3)
    magnitude, angle = cv2.cartToPolar(gx, gy)  # angle in [0, 2 pi)
    orient = (angle * (n_orient / (2 * np.pi))).astype(np.int32) % n_orient
    return orient, magnitude


def gradient_descriptors(orient: np.ndarray, magnitude: np.ndarray, centres: np.ndarray, size: tuple[int, int],
                         cells: int = 4, n_orient: int = 8) -> np.ndarray:
    """Gradient-orientation vectors (n, cells * cells * n_orient) of the regions (Li et al. 2007, Fig. 1, after SIFT).

    Each pixel's magnitude, weighted by a Gaussian centred on the region (sigma = half its width), is added to its
    cell's orientation bin; vectors are L2-normalised so distances compare across regions and contrasts.
    """
    w, h = size
    flat, inside = _region_pixels(np.asarray(centres, float).reshape(-1, 2), size, orient.shape)
    yy, xx = np.mgrid[0:h, 0:w]
    cell = (yy * cells // h) * cells + (xx * cells // w)  # (h, w) cell of each region pixel
    gauss = np.exp(-(((xx - (w - 1) / 2) ** 2) + ((yy - (h - 1) / 2) ** 2)) / (2 * (w / 2) ** 2))
    n_bins = cells * cells * n_orient
    weight = gauss[None] * magnitude.ravel().take(flat)
    vec = _binned(cell[None] * n_orient + orient.ravel().take(flat), n_bins, flat, inside, weight)
    norm = np.linalg.norm(vec, axis=1, keepdims=True)
    return vec / np.where(norm > 0, norm, 1.0)

"""Re-identification for the LMB tracker (Jiang and Yang): LOMO features (Liao et al. 2015) and the XQDA
metric learned on crops the simulator renders, plus the FIFO feature pool that gives a newborn track the label of a
target seen before.

LOMO, scaled down to our small targets: each crop is resized to 48 x 24, lit evenly by a two-scale Retinex,
and described on a 3-level pyramid by 8 x 8 windows (stride 4) holding an 8 x 8 x 8 HSV histogram and two
scale-invariant local ternary pattern (SILTP) histograms (radius 1 and 2, tau 0.3, 81 bins each); windows of one
row are max-pooled (the horizontal maximum that makes LOMO robust to viewpoint), the result log-scaled and each
part normalised to unit length. XQDA projects the feature onto r directions that separate "same target at two
times" from "two targets" and measures a quadratic distance there; `mtt-sim learn-reid` learns it.
"""

from __future__ import annotations

from collections import deque
from pathlib import Path

import cv2
import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

CROP = (24, 48)           # width, height of the resized crop
WINDOW, STRIDE = 8, 4
HSV_BINS, TAU = 8, 0.3
LEVELS = 3                # pyramid levels (halving each time; a level narrower than a window is skipped)
_ROWS = sum(((CROP[1] >> k) - WINDOW) // STRIDE + 1 for k in range(LEVELS) if min(CROP) >> k >= WINDOW)
_DIM = _ROWS * (HSV_BINS ** 3 + 2 * 81)  # windows' rows over the pyramid levels, times the bins of each part
METRIC_FILE = Path(__file__).parent.parent / "data" / "xqda.npz"


def retinex(imgs: np.ndarray, sigmas=(2.0, 8.0)) -> np.ndarray:
    """Multi-scale Retinex of images (k, h, w, 3): log image minus log of its blurs, stretched back to 0..255 per
    image and channel (uint8)."""
    f = imgs.astype(np.float32) + 1.0
    out = sum(np.log(f) - np.log(np.stack([cv2.GaussianBlur(one, (0, 0), s) for one in f])) for s in sigmas) / len(sigmas)
    pixels = out.reshape(len(out), -1, 3)  # a reduction over one axis: several times faster than over (1, 2)
    lo, hi = pixels.min(axis=1)[:, None, None], pixels.max(axis=1)[:, None, None]
    return np.clip((out - lo) / np.maximum(hi - lo, 1e-6) * 255, 0, 255).astype(np.uint8)


def _siltp(grey: np.ndarray, radius: int) -> np.ndarray:
    """Per-pixel SILTP code (0..80) of images (k, h, w) from the 4 neighbours at `radius` (edges replicated)."""
    g = np.pad(grey, ((0, 0), (radius, radius), (radius, radius)), mode="edge")
    h, w = grey.shape[1:]
    centre = g[:, radius:radius + h, radius:radius + w]
    code = np.zeros(grey.shape, np.int64)
    for k, (dy, dx) in enumerate(((0, radius), (-radius, 0), (0, -radius), (radius, 0))):
        n = g[:, radius + dy:radius + dy + h, radius + dx:radius + dx + w]
        code += 3 ** k * ((n > (1 + TAU) * centre) + 2 * (n < (1 - TAU) * centre))
    return code


def _pooled_histograms(codes: np.ndarray, n_bins: int) -> np.ndarray:
    """(k, rows_of_windows * n_bins): histograms of every WINDOW x WINDOW window of code maps (k, h, w), max over
    each row of windows."""
    windows = sliding_window_view(codes, (WINDOW, WINDOW), axis=(1, 2))[:, ::STRIDE, ::STRIDE]   # (k, R, C, W, W)
    k, r, c = windows.shape[:3]
    index = (np.arange(k * r * c)[:, None] * n_bins + windows.reshape(k * r * c, -1)).ravel()
    hist = np.bincount(index, minlength=k * r * c * n_bins).reshape(k, r, c, n_bins)
    return hist.max(axis=2).reshape(k, -1)


def _each(imgs: np.ndarray, fn) -> np.ndarray:
    """An OpenCV call made image by image on a stack of images, stacked again."""
    return np.stack([fn(one) for one in imgs])


def lomo(crops) -> np.ndarray:
    """The LOMO features (k, d) of k RGB crops of any sizes, computed together: each is resized to CROP, and every
    step after that runs on all of them at once (five crops: 3.4 ms together, 1.4 ms each alone)."""
    if not len(crops):
        return np.zeros((0, _DIM), np.float32)
    imgs = retinex(np.stack([cv2.resize(np.ascontiguousarray(c), CROP, interpolation=cv2.INTER_AREA) for c in crops]))
    colour, texture = [], []
    for _ in range(LEVELS):
        if min(imgs.shape[1:3]) < WINDOW:
            break
        hsv = _each(imgs, lambda one: cv2.cvtColor(one, cv2.COLOR_RGB2HSV)).astype(np.int64)
        bins = ((hsv[..., 0] * HSV_BINS // 180) * HSV_BINS + hsv[..., 1] * HSV_BINS // 256) * HSV_BINS \
            + hsv[..., 2] * HSV_BINS // 256
        colour.append(_pooled_histograms(bins, HSV_BINS ** 3))
        grey = _each(imgs, lambda one: cv2.cvtColor(one, cv2.COLOR_RGB2GRAY)).astype(np.float32)
        texture += [_pooled_histograms(_siltp(grey, r), 81) for r in (1, 2)]
        imgs = _each(imgs, lambda one: cv2.resize(one, (one.shape[1] // 2, one.shape[0] // 2), interpolation=cv2.INTER_AREA))
    parts = [np.log1p(np.concatenate(p, axis=1).astype(np.float32)) for p in (colour, texture)]
    # each row's norm on its own: norm(p, axis=1) sums in another order and differs in the last bit from one crop's
    # feature, which the shipped metric and the published results were computed with
    return np.concatenate([p / np.maximum([np.linalg.norm(row) for row in p], 1e-12)[:, None] for p in parts], axis=1)


def crops(frame: np.ndarray, boxes: np.ndarray) -> list[np.ndarray]:
    """The frame's pixels inside each box (x, y, w, h), clipped to the frame, at least 2 x 2."""
    h, w = frame.shape[:2]
    out = []
    for x, y, bw, bh in np.asarray(boxes, float):
        x0, y0 = int(np.clip(x, 0, w - 2)), int(np.clip(y, 0, h - 2))
        x1, y1 = int(np.clip(np.ceil(x + bw), x0 + 2, w)), int(np.clip(np.ceil(y + bh), y0 + 2, h))
        out.append(frame[y0:y1, x0:x1])
    return out


def learn_xqda(features: np.ndarray, classes: np.ndarray, dims: int = 16, pca: int = 200,
               rng: np.random.Generator | None = None) -> dict:
    """XQDA (Liao et al. 2015) on PCA-reduced features: W = the leading generalised eigenvectors of
    (Sigma_E, Sigma_I), the covariances of feature differences between different targets and within one target,
    and M = (W' Sigma_I W)^-1 - (W' Sigma_E W)^-1. Returns the arrays `distance` needs."""
    from scipy.linalg import eigh

    rng = rng or np.random.default_rng(0)
    x = np.asarray(features, np.float64)
    mean = x.mean(axis=0)
    _, _, vt = np.linalg.svd(x - mean, full_matrices=False)
    basis = vt[:pca].T                                          # (d, pca)
    y = (x - mean) @ basis
    same = classes[:, None] == classes[None]
    i, j = np.nonzero(np.triu(same, 1))
    diff_i = y[i] - y[j]
    a, b = rng.integers(len(y), size=(2, 20 * len(diff_i) + 1000))
    diff_e = (y[a] - y[b])[classes[a] != classes[b]]
    sigma_i = diff_i.T @ diff_i / len(diff_i) + 1e-3 * np.eye(y.shape[1])
    sigma_e = diff_e.T @ diff_e / len(diff_e)
    values, vectors = eigh(sigma_e, sigma_i)
    w = vectors[:, np.argsort(values)[::-1][:dims]]
    m = np.linalg.inv(w.T @ sigma_i @ w) - np.linalg.inv(w.T @ sigma_e @ w)
    return {"mean": mean.astype(np.float32), "projection": (basis @ w).astype(np.float32),
            "kernel": m.astype(np.float32)}


class Metric:
    """The learned XQDA metric: distance(a, b) = (a - b)' P M P' (a - b)."""

    def __init__(self, arrays: dict):
        self.mean, self.projection, self.kernel = (np.asarray(arrays[k], np.float32)
                                                   for k in ("mean", "projection", "kernel"))

    @classmethod
    def from_file(cls, path: str | Path = "") -> "Metric":
        """The metric saved at `path` by `mtt-sim learn-reid`; the shipped one (METRIC_FILE) by default."""
        path = Path(path or METRIC_FILE)
        if not path.is_file():
            raise ValueError(f"{path} not found: make it with `mtt-sim learn-reid --out {path}`")
        try:
            with np.load(path) as f:
                return cls(dict(f))
        except (OSError, ValueError, KeyError):
            raise ValueError(f"{path} is not a metric file written by `mtt-sim learn-reid`") from None

    def embed(self, features: np.ndarray) -> np.ndarray:
        return (np.asarray(features, np.float32).reshape(-1, len(self.mean)) - self.mean) @ self.projection

    def distance(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """(len(a), len(b)) XQDA distances between embedded features."""
        d = a[:, None, :] - b[None, :, :]
        return np.einsum("abi,ij,abj->ab", d, self.kernel, d)


class FeaturePool:
    """A FIFO of (embedded feature, label) from confident, associated detections (sec. 4.4.2)."""

    def __init__(self, size: int):
        self.items: deque = deque(maxlen=max(1, size))

    def add(self, embedded: np.ndarray, labels: np.ndarray) -> None:
        self.items.extend(zip(embedded, labels.tolist()))

    def match(self, metric: Metric, embedded: np.ndarray, exclude: set, threshold: float) -> np.ndarray:
        """For each embedded feature, the label of the nearest pooled feature whose label is not in `exclude` and
        lies within `threshold`, else 0. Each label is given at most once (nearest first)."""
        out = np.zeros(len(embedded), np.int64)
        pool = [(f, l) for f, l in self.items if l not in exclude]
        if not pool or not len(embedded):
            return out
        d = metric.distance(embedded, np.stack([f for f, _ in pool]))
        labels = np.array([l for _, l in pool])
        taken = set()
        for flat in np.argsort(d, axis=None):
            i, k = np.unravel_index(flat, d.shape)
            if d[i, k] > threshold:
                break
            if out[i] == 0 and labels[k] not in taken:
                out[i] = labels[k]
                taken.add(labels[k])
        return out

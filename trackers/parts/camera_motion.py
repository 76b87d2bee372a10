"""Camera-motion compensation (CMC), as BoT-SORT's global motion compensation (Aharon, Orfaig and Bobrovsky 2022):
estimate the image's motion between consecutive frames as a 2x3 warp A (a point p of the last frame is at A [p; 1]
in this one) and apply it to the trackers' predicted states before association, so that a shaking or moving camera
does not move every target out of its gate.

Two estimators, each on the grey frame shrunk by `downscale`:
- `sparse_flow`: corners of the last frame outside its detections (the people move on their own), followed by
  pyramidal Lucas-Kanade optical flow, and a rotation, scale and translation fitted to them with RANSAC;
- `ecc`: the Euclidean (rotation and translation) warp maximising the enhanced correlation coefficient
  (Evangelidis and Psarakis 2008) between the two frames.
Either falls back to no motion where it finds none (too few corners, no convergence).
"""

from __future__ import annotations

import cv2
import numpy as np

METHODS = ("none", "ecc", "sparse_flow")
IDENTITY = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])


class CameraMotion:
    """The camera's motion from frame to frame by `method` (one of METHODS; "none" is always the identity)."""

    def __init__(self, method: str = "none", downscale: int = 2):
        if method not in METHODS:
            raise ValueError(f"cmc={method!r}: allowed: {', '.join(map(repr, METHODS))}")
        self.method, self.downscale = method, downscale
        self.last: np.ndarray | None = None
        self.last_boxes = np.zeros((0, 4))

    def estimate(self, frame: np.ndarray | None, boxes: np.ndarray | None = None) -> np.ndarray:
        """The 2x3 warp from the last frame to `frame` (RGB, (H, W, 3) uint8); `boxes` (x, y, w, h) are this
        frame's detections, whose pixels the next estimate does not follow. The first frame gives the identity."""
        if self.method == "none":
            return IDENTITY.copy()
        grey = cv2.cvtColor(frame, cv2.COLOR_RGB2GRAY)
        if self.downscale > 1:
            grey = cv2.resize(grey, (grey.shape[1] // self.downscale, grey.shape[0] // self.downscale),
                              interpolation=cv2.INTER_AREA)
        warp = IDENTITY.copy()
        if self.last is not None and self.last.shape == grey.shape:
            found = self._sparse_flow(self.last, grey) if self.method == "sparse_flow" else self._ecc(self.last, grey)
            if found is not None:
                warp = found
                warp[:, 2] *= self.downscale
        self.last, self.last_boxes = grey, np.zeros((0, 4)) if boxes is None else np.asarray(boxes, float).reshape(-1, 4)
        return warp

    def _sparse_flow(self, last: np.ndarray, grey: np.ndarray) -> np.ndarray | None:
        mask = np.full(last.shape, 255, np.uint8)
        for x, y, w, h in np.round(self.last_boxes / self.downscale).astype(int):
            mask[max(y, 0):max(y + h, 0), max(x, 0):max(x + w, 0)] = 0
        corners = cv2.goodFeaturesToTrack(last, maxCorners=1000, qualityLevel=0.01, minDistance=1, blockSize=3,
                                          mask=mask, useHarrisDetector=False, k=0.04)
        if corners is None or len(corners) < 5:
            return None
        moved, status, _ = cv2.calcOpticalFlowPyrLK(last, grey, corners, None)
        good = status.ravel() == 1
        if good.sum() < 5:
            return None
        warp, _ = cv2.estimateAffinePartial2D(corners[good], moved[good], method=cv2.RANSAC)
        return warp

    def _ecc(self, last: np.ndarray, grey: np.ndarray) -> np.ndarray | None:
        warp = np.eye(2, 3, dtype=np.float32)
        criteria = (cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, 100, 1e-5)
        try:
            _, warp = cv2.findTransformECC(last, grey, warp, cv2.MOTION_EUCLIDEAN, criteria, None, 1)
        except cv2.error:
            return None
        return warp.astype(float)


def warp_centres(x: np.ndarray, P: np.ndarray, A: np.ndarray, layout: str) -> tuple[np.ndarray, np.ndarray]:
    """Kalman states x (n, d) and covariances P (n, d, d) moved by the 2x3 warp A. `layout` says where the box is:
    "centre_area" (SORT's cx, cy, s, r, vcx, vcy, vs: the centre moves, the area scales by det A),
    "corner_size" (LMB's x, y, w, h, vx, vy, vw, vh: the centre moves, the size scales by sqrt(det A)) or
    "centre_aspect_height" (ByteTrack's cx, cy, a, h, vcx, vcy, va, vh: the centre moves, the height scales by
    sqrt(det A)); velocities turn and scale with the warp's linear part."""
    if np.array_equal(A, IDENTITY) or not len(x):
        return x, P
    L, t = A[:, :2], A[:, 2]
    s = float(np.sqrt(abs(np.linalg.det(L))))
    x = x.copy()
    d = x.shape[1]
    T = np.eye(d)
    if layout == "centre_area":
        x[:, :2] = x[:, :2] @ L.T + t
        x[:, 4:6] = x[:, 4:6] @ L.T
        x[:, [2, 6]] *= s * s
        T[:2, :2] = T[4:6, 4:6] = L
        T[2, 2] = T[6, 6] = s * s
    elif layout == "corner_size":
        centre = x[:, :2] + x[:, 2:4] / 2
        x[:, 2:4] *= s
        x[:, :2] = centre @ L.T + t - x[:, 2:4] / 2
        x[:, 4:6] = x[:, 4:6] @ L.T
        x[:, 6:8] *= s
        T[:2, :2] = T[4:6, 4:6] = L
        T[:2, 2:4] = (L - s * np.eye(2)) / 2  # the corner moves with the centre, less half the size's change
        T[2, 2] = T[3, 3] = T[6, 6] = T[7, 7] = s
    elif layout == "centre_aspect_height":
        x[:, :2] = x[:, :2] @ L.T + t
        x[:, 4:6] = x[:, 4:6] @ L.T
        x[:, [3, 7]] *= s
        T[:2, :2] = T[4:6, 4:6] = L
        T[3, 3] = T[7, 7] = s
    else:
        raise ValueError(f"layout={layout!r}: allowed: 'centre_area', 'corner_size', 'centre_aspect_height'")
    return x, T @ P @ T.T


def warp_boxes(boxes: np.ndarray, A: np.ndarray) -> np.ndarray:
    """Boxes x, y, w, h moved by the 2x3 warp A (centre moved, size scaled by sqrt(det A))."""
    if np.array_equal(A, IDENTITY) or not len(boxes):
        return boxes
    s = float(np.sqrt(abs(np.linalg.det(A[:, :2]))))
    size = boxes[:, 2:4] * s
    centre = (boxes[:, :2] + boxes[:, 2:4] / 2) @ A[:, :2].T + A[:, 2]
    return np.concatenate([centre - size / 2, size], axis=1)

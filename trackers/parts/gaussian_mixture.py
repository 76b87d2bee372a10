"""Gaussian components of boxes for the random-finite-set trackers (LMB, GM-PHD), many at once.

A component's state is (x, y, w, h, vx, vy, vw, vh): the box's top-left corner and size with their rates (the
state of the LMB tracker), moved by a constant-velocity model; the measurement is the box (x, y, w, h). Process and
measurement noise scale with each component's box size, so one model serves 20-pixel and 200-pixel targets.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..base import Param
from .near_pairs import near_in_x_and_y

DIM, MEAS = 8, 4
# the model parameters the LMB and GM-PHD trackers share; noise values chosen on mot17_like seed 100 (not one
# of the experiments' seeds 0..9)
MODEL_PARAMETERS = {
    "survival": Param(0.98, "(0, 1]", "probability a target survives a frame", (0.9, 0.999)),
    "detection": Param(0.75, "(0, 1]", "detection probability P_D", (0.4, 0.98)),
    "clutter_rate": Param(5.0, "(0, inf)", "false detections per frame", (0.5, 50.0, "log")),
    "gate": Param(0.99, "(0, 1)", "chi-square gate probability", (0.9, 0.9999)),
    "measurement_noise": Param(0.15, "(0, inf)", "detection noise, as a fraction of the box size", (0.05, 0.6, "log")),
    "process_noise": Param(0.01, "(0, inf)", "motion noise per frame, as a fraction of the box size",
                           (0.002, 0.1, "log"))}
F = np.eye(DIM) + np.eye(DIM, k=MEAS)
H = np.eye(MEAS, DIM)


@dataclass(frozen=True)
class BoxNoise:
    """Standard deviations relative to the box size: of the measured box (measurement), of the velocity change per
    frame (process), and of a newborn component's velocity."""

    measurement: float = 0.05
    process: float = 0.02
    birth_velocity: float = 0.1

    def scale(self, m: np.ndarray) -> np.ndarray:
        """(n, 4): each component's w, h, w, h (at least one pixel), the unit its noise is expressed in."""
        wh = np.maximum(m[:, 2:4], 1.0)
        return np.concatenate([wh, wh], axis=1)

    def measurement_covariance(self, m: np.ndarray) -> np.ndarray:
        return _diag((self.measurement * self.scale(m)) ** 2)

    def process_covariance(self, m: np.ndarray) -> np.ndarray:
        """White-noise acceleration: G diag(q^2) G^T with G = [I/2; I] per component."""
        q2 = (self.process * self.scale(m)) ** 2
        cov = np.zeros((len(m), DIM, DIM))
        for a, b, f in ((0, 0, 0.25), (0, 4, 0.5), (4, 0, 0.5), (4, 4, 1.0)):
            idx = np.arange(MEAS)
            cov[:, a + idx, b + idx] = f * q2
        return cov

    def birth(self, boxes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Means and covariances of components born at measured boxes (n, 4), at rest."""
        m = np.concatenate([boxes, np.zeros_like(boxes)], axis=1)
        s = self.scale(m)
        return m, _diag(np.concatenate([(self.measurement * s) ** 2, (self.birth_velocity * s) ** 2], axis=1))


def _diag(v: np.ndarray) -> np.ndarray:
    out = np.zeros(v.shape + (v.shape[-1],))
    idx = np.arange(v.shape[-1])
    out[..., idx, idx] = v
    return out


def predict(m: np.ndarray, P: np.ndarray, noise: BoxNoise) -> tuple[np.ndarray, np.ndarray]:
    """Constant-velocity prediction of every component; sizes are kept positive."""
    m = m @ F.T
    m[:, 2:4] = np.maximum(m[:, 2:4], 1.0)
    return m, F @ P @ F.T + noise.process_covariance(m)


@dataclass
class Innovation:
    """Every component's predicted measurement, innovation covariance, gain and corrected covariance."""

    eta: np.ndarray      # (n, 4)
    S_inv: np.ndarray    # (n, 4, 4)
    S_diag: np.ndarray   # (n, 4): variances of the predicted measurement
    log_norm: np.ndarray  # (n,): log of the Gaussian's normalising constant
    K: np.ndarray        # (n, 8, 4)
    P: np.ndarray        # (n, 8, 8): covariance after any measurement

    @classmethod
    def of(cls, m: np.ndarray, P: np.ndarray, noise: BoxNoise) -> "Innovation":
        S = H @ P @ H.T + noise.measurement_covariance(m)
        S_inv = np.linalg.inv(S)
        K = P @ H.T @ S_inv
        _, logdet = np.linalg.slogdet(S)
        return cls(m @ H.T, S_inv, np.diagonal(S, axis1=1, axis2=2), -0.5 * (MEAS * np.log(2 * np.pi) + logdet), K,
                   P - K @ H @ P)

    def distance2(self, z: np.ndarray, gate: float = np.inf) -> np.ndarray:
        """(n, M) squared Mahalanobis distances of measurements z (M, 4); with a gate, inf for the pairs beyond it
        (only pairs within the gate in x and in y alone are computed, see `near_in_x_and_y`)."""
        if np.isinf(gate):
            d = z[None, :, :] - self.eta[:, None, :]
            return np.einsum("nmi,nij,nmj->nm", d, self.S_inv, d)
        out = np.full((len(self.eta), len(z)), np.inf)
        k, j = near_in_x_and_y(self.eta[:, :2], np.sqrt(gate * self.S_diag[:, :2]), z[:, :2])
        d = z[j] - self.eta[k]
        out[k, j] = np.einsum("pi,pij,pj->p", d, self.S_inv[k], d)
        return np.where(out < gate, out, np.inf)

    def log_likelihood(self, distance2: np.ndarray) -> np.ndarray:
        return self.log_norm[:, None] - 0.5 * distance2

    def corrected_means(self, m: np.ndarray, z: np.ndarray, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """Means of components `rows` corrected by measurements `cols` (pairs)."""
        return m[rows] + np.einsum("nij,nj->ni", self.K[rows], z[cols] - self.eta[rows])


def within_distance(m: np.ndarray, P: np.ndarray, limit: float) -> list[np.ndarray]:
    """For each component k, the components n (k among them) with (m_n - m_k)' P_k^-1 (m_n - m_k) <= limit
    (candidates: within the bound in x and in y alone, see `near_in_x_and_y`)."""
    k, cand = near_in_x_and_y(m[:, :2], np.sqrt(limit * np.maximum(P[:, [0, 1], [0, 1]], 0)), m[:, :2])
    d = m[cand] - m[k]
    close = np.einsum("pi,pij,pj->p", d, np.linalg.inv(P)[k], d) <= limit
    k, cand = k[close], cand[close]
    by_k = np.lexsort((cand, k))
    return np.split(cand[by_k], np.searchsorted(k[by_k], np.arange(1, len(m))))

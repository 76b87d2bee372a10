"""Linear Kalman filters with constant-velocity models, many at once.

A `KalmanBank` holds N independent filters that share their model matrices as stacked arrays
(x: (N, d), P: (N, d, d)), so predicting or updating every track is a few batched matrix
products instead of a Python loop over track objects. The `xyah_*` functions are ByteTrack's filter, whose
noise scales with each box's height, on stacked means and covariances in the same way.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Model:
    """F (transition), H (measurement), Q (process noise), R (measurement noise), P0 (initial covariance)."""

    F: np.ndarray
    H: np.ndarray
    Q: np.ndarray
    R: np.ndarray
    P0: np.ndarray


def box_model() -> Model:
    """SORT's model (Bewley et al. 2016): state (cx, cy, s, r, vcx, vcy, vs), measurement (cx, cy, s, r),
    s = area, r = aspect ratio w / h held constant; the noise values of the SORT reference code."""
    F = np.eye(7)
    F[0, 4] = F[1, 5] = F[2, 6] = 1.0
    H = np.eye(4, 7)
    Q = np.diag([1.0, 1.0, 1.0, 1.0, 0.01, 0.01, 1e-4])
    R = np.diag([1.0, 1.0, 10.0, 10.0])
    P0 = np.diag([10.0, 10.0, 10.0, 10.0, 1e4, 1e4, 1e4])
    return Model(F, H, Q, R, P0)


def point_model(accel_sigma: float = 1.0, meas_sigma: float = 2.0, vel_sigma0: float = 10.0) -> Model:
    """Constant velocity in the plane: state (px, py, vx, vy), measurement (px, py); white-noise acceleration."""
    F = np.eye(4)
    F[0, 2] = F[1, 3] = 1.0
    G = np.array([[0.5, 0.0], [0.0, 0.5], [1.0, 0.0], [0.0, 1.0]])
    return Model(F, np.eye(2, 4), accel_sigma**2 * G @ G.T, meas_sigma**2 * np.eye(2),
                 np.diag([meas_sigma**2, meas_sigma**2, vel_sigma0**2, vel_sigma0**2]))


def stop_shrinking_to_nothing(bank: "KalmanBank") -> None:
    """Box model: zero the area velocity where the next prediction would make the area negative (as SORT does)."""
    bank.x[bank.x[:, 2] + bank.x[:, 6] <= 0, 6] = 0.0


# ByteTrack's filter (DeepSORT's): state (cx, cy, aspect, height) and their velocities, noise proportional to the height
_POSITION, _VELOCITY = 1 / 20, 1 / 160
_F8 = np.eye(8) + np.eye(8, k=4)
_DIAG8, _DIAG4 = np.arange(8), np.arange(4)


def _noise_rule(weights: list[float], fixed: dict[int, float]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A diagonal noise: standard deviation weight x height per entry, except the `fixed` entries; as (weights,
    which entries are fixed, their variances), worked out once for _variances."""
    is_fixed = np.isin(np.arange(len(weights)), list(fixed))
    values = np.zeros(len(weights))
    values[list(fixed)] = list(fixed.values())
    return np.array(weights), is_fixed, np.square(values)


_INITIAL = _noise_rule([2 * _POSITION] * 4 + [10 * _VELOCITY] * 4, {2: 1e-2, 6: 1e-5})
_PROCESS = _noise_rule([_POSITION] * 4 + [_VELOCITY] * 4, {2: 1e-2, 6: 1e-5})
_MEASUREMENT = _noise_rule([_POSITION] * 4, {2: 1e-1})


def _variances(height: np.ndarray, rule: tuple[np.ndarray, np.ndarray, np.ndarray]) -> np.ndarray:
    """(n, d) variances of a _noise_rule for tracks of these heights."""
    weights, is_fixed, fixed = rule
    return np.where(is_fixed, fixed, np.square(height[:, None] * weights))


def xyah_initiate(z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """New tracks at measurements z (n, 4) cx, cy, aspect, height: means (n, 8) and covariances (n, 8, 8)."""
    cov = np.zeros((len(z), 8, 8))
    cov[:, _DIAG8, _DIAG8] = _variances(z[:, 3], _INITIAL)
    return np.concatenate([z, np.zeros_like(z)], axis=1), cov


def xyah_predict(mean: np.ndarray, cov: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """One constant-velocity step, with process noise scaled by each track's height."""
    cov = _F8 @ cov @ _F8.T
    cov[:, _DIAG8, _DIAG8] += _variances(mean[:, 3], _PROCESS)
    return mean @ _F8.T, cov


def xyah_update(mean: np.ndarray, cov: np.ndarray, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Correct with measurements z (n, 4), measurement noise scaled by the predicted height. H selects the first four
    entries, so H P H^T, P H^T and H x are slices."""
    S = cov[:, :4, :4].copy()
    S[:, _DIAG4, _DIAG4] += _variances(mean[:, 3], _MEASUREMENT)
    K = np.linalg.solve(S, cov[:, :4, :]).transpose(0, 2, 1)  # P H^T S^-1
    innovation = z - mean[:, :4]
    return mean + np.einsum("nij,nj->ni", K, innovation), cov - K @ S @ K.transpose(0, 2, 1)


class KalmanBank:
    """N Kalman filters sharing one Model."""

    def __init__(self, model: Model):
        self.m = model
        d = model.F.shape[0]
        self.x, self.P = np.zeros((0, d)), np.zeros((0, d, d))

    def __len__(self) -> int:
        return len(self.x)

    def add(self, z: np.ndarray) -> None:
        """Start filters at measurements z (n, k): measured entries set, the rest zero, covariance P0."""
        z = np.asarray(z, float).reshape(-1, self.m.H.shape[0])
        x = z @ self.m.H  # H is a selection matrix: this places each measurement in its state entries
        self.x = np.concatenate([self.x, x])
        self.P = np.concatenate([self.P, np.broadcast_to(self.m.P0, (len(z),) + self.m.P0.shape)])

    def keep(self, mask: np.ndarray) -> None:
        self.x, self.P = self.x[mask], self.P[mask]

    def predict(self) -> None:
        F = self.m.F
        self.x = self.x @ F.T
        self.P = F @ self.P @ F.T + self.m.Q

    def innovation_covariance(self, rows=slice(None)) -> np.ndarray:
        H = self.m.H
        return H @ self.P[rows] @ H.T + self.m.R

    def measurement(self) -> np.ndarray:
        """Predicted measurements (N, k)."""
        return self.x @ self.m.H.T

    def mahalanobis(self, z: np.ndarray) -> np.ndarray:
        """(N, M) squared Mahalanobis distances of measurements z (M, k) from each filter's prediction."""
        diff = np.asarray(z, float)[None, :, :] - self.measurement()[:, None, :]
        S_inv = np.linalg.inv(self.innovation_covariance())
        return np.einsum("nmi,nij,nmj->nm", diff, S_inv, diff)

    def update(self, rows: np.ndarray, z: np.ndarray) -> None:
        """Correct filters `rows` with measurements z (len(rows), k)."""
        if not len(rows):
            return
        H, P = self.m.H, self.P[rows]
        S = H @ P @ H.T + self.m.R
        K = np.linalg.solve(S, H @ P).transpose(0, 2, 1)  # P H^T S^-1, using the symmetry of P and S
        innovation = np.asarray(z, float) - self.x[rows] @ H.T
        self.x[rows] += np.einsum("nij,nj->ni", K, innovation)
        self.P[rows] = P - K @ H @ P

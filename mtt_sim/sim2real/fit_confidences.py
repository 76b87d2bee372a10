"""The synthetic detector's confidences fitted to real detections (`mtt-sim calibrate`).

A real detector's confidences are skewed toward the top for good boxes and lower for poor ones; a tracker's
confidence threshold acts on that lower tail, so the fit is by likelihood, not by the mean and variance alone.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import least_squares, minimize, minimize_scalar
from scipy.special import betaln, expit, logit

from mtt_sim.sim.sensor import log_height


def fit(a, reference: float) -> dict:
    """The confidence keys fitted to associated detections `a` (a `calibrate.Associated`; `reference`: the height
    from which size no longer helps, px): offset and scale from the range; the good boxes' mean (logistic in
    visibility and height, as `sensor.true_confidence`) and Beta concentration by maximum likelihood; the outliers'
    shift of that mean's logit by maximum likelihood given them; the false positives' Beta by moments (their
    quantiles already match). Matched by moments, the good boxes' confidences spread low, and a tracker's threshold
    dropped true detections in the twin where it drops false ones on real video."""
    lo, hi = float(a.det_conf.min()), float(a.det_conf.max())
    pad = 0.01 * max(hi - lo, 1e-3)
    offset, scale = lo - pad, (hi - lo) + 2 * pad
    y = np.clip((a.conf - offset) / scale, 1e-6, 1 - 1e-6)
    x = np.c_[a.visibility - 1, log_height(a.height, reference)]
    good, poor = a.hit, a.detected & ~a.hit
    start = least_squares(lambda b: expit(b[0] + x[good] @ b[1:]) - y[good],
                          np.array([logit(np.clip(y[good].mean(), 0.02, 0.98)), 0.0, 0.0])).x
    theta = minimize(lambda t: _beta_cost(y[good], t[0] + x[good] @ t[1:3], math.exp(t[3])),
                     np.r_[start, math.log(4.0)], method="L-BFGS-B",
                     bounds=[(-20, 20), (0, 100), (-10, 10), (math.log(0.5), math.log(1e4))]).x
    b, spread = theta[:3], math.exp(theta[3])
    shift = 0.0
    if poor.sum() >= 10:
        shift = minimize_scalar(lambda s: _beta_cost(y[poor], b[0] + x[poor] @ b[1:] + s, spread),
                                bounds=(-20, 20), method="bounded").x
    f = (a.det_conf[a.det_kind == 2] - offset) / scale
    false_mean = float(f.mean()) if len(f) else 0.35
    false_spread = false_mean * (1 - false_mean) / max(float(f.var()), 1e-12) - 1 if len(f) > 1 else 0.0
    return {"conf_true": float(np.clip(expit(b[0]), 0.01, 0.99)), "conf_visibility": float(b[1]),
            "conf_height": float(b[2]), "conf_spread": spread, "conf_outlier": float(shift),
            "conf_false": float(np.clip(false_mean, 0.01, 0.99)),
            "conf_false_spread": float(np.clip(false_spread, 0.5, 1e4)), "conf_offset": offset, "conf_scale": scale}


def _beta_cost(y: np.ndarray, eta: np.ndarray, k: float) -> float:
    """Mean negative log-likelihood of `y` under Beta draws of mean expit(eta) and concentration k."""
    m = np.clip(expit(eta), 1e-6, 1 - 1e-6)
    alpha, beta = m * k, (1 - m) * k
    return float(-np.mean((alpha - 1) * np.log(y) + (beta - 1) * np.log1p(-y) - betaln(alpha, beta)))

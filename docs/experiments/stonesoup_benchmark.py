"""A textbook benchmark that holds jpda against an independent implementation: point targets from Stone Soup's
simulator, tracked by Stone Soup's JPDA with EHM and by our jpda and gnn on the very same detections; GOSPA, ids used
and tracker time per frame.

The world: 20 targets under Stone Soup's ConstantVelocity(0.05) (a velocity variance of 0.05 per step, so our
accel_sigma = sqrt(0.05) = 0.224, a discrete white acceleration with the same velocity noise), measured with
variance 1 (meas_sigma 1), P_D 0.9 and 5 clutter points a scan uniform over a 400 x 400 square, 200 scans. Our
trackers see each measurement as a 2 x 2 box around it. GOSPA: c = 10, p = 1, alpha = 2, mean per scan after
scan 20. Needs Stone Soup, which mtt-sim does not depend on: run it from an environment that has both
(`pip install stonesoup` beside mtt-sim):

    python docs/experiments/stonesoup_benchmark.py --seeds 5
"""

from __future__ import annotations

import argparse
import datetime
import statistics
import time

import numpy as np
from stonesoup.dataassociator.neighbour import GNNWith2DAssignment
from stonesoup.dataassociator.probability import JPDAwithEHM
from stonesoup.deleter.error import CovarianceBasedDeleter
from stonesoup.hypothesiser.distance import DistanceHypothesiser
from stonesoup.hypothesiser.probability import PDAHypothesiser
from stonesoup.initiator.simple import MultiMeasurementInitiator
from stonesoup.measures import Mahalanobis
from stonesoup.models.measurement.linear import LinearGaussian
from stonesoup.models.transition.linear import CombinedLinearGaussianTransitionModel, ConstantVelocity
from stonesoup.predictor.kalman import KalmanPredictor
from stonesoup.simulator.simple import MultiTargetGroundTruthSimulator, SimpleDetectionSimulator
from stonesoup.tracker.simple import MultiTargetMixtureTracker
from stonesoup.types.array import StateVector
from stonesoup.types.state import GaussianState
from stonesoup.updater.kalman import KalmanUpdater

from mtt_sim.metrics import gospa_of_points
from mtt_sim.trackers import make

TARGETS, SCANS, PD, CLUTTER, HALF_WIDTH, Q, R = 20, 200, 0.9, 5.0, 200.0, 0.05, 1.0
DENSITY = CLUTTER / (2 * HALF_WIDTH) ** 2
C, P, FROM_SCAN = 10.0, 1.0, 20
DELETE_TRACE = 6.0  # the best of 4, 6, 10 and 20 for Stone Soup on seed 0 (GOSPA 23.7, 22.0, 22.4, 31.0)
OURS = {"jpda": f"jpda:min_hits=2,pd={PD},clutter_density={DENSITY},accel_sigma={Q ** 0.5:.4f},meas_sigma={R ** 0.5}",
        "gnn": f"gnn:min_hits=2,accel_sigma={Q ** 0.5:.4f},meas_sigma={R ** 0.5}"}


def simulate(seed: int) -> tuple[list[np.ndarray], list[set], list]:
    """Per scan: the true positions (n, 2), the detections (Stone Soup objects) and their (m, 2) positions."""
    start = datetime.datetime(2026, 1, 1)
    transition = CombinedLinearGaussianTransitionModel([ConstantVelocity(Q), ConstantVelocity(Q)])
    rng = np.random.default_rng(seed)
    np.random.seed(seed)  # Stone Soup's models draw their noise from numpy's global generator
    starts = [StateVector([x, vx, y, vy]) for x, y, vx, vy in
              zip(*rng.uniform(-0.6 * HALF_WIDTH, 0.6 * HALF_WIDTH, (2, TARGETS)), *rng.normal(0, 1.0, (2, TARGETS)))]
    truth = MultiTargetGroundTruthSimulator(
        transition_model=transition, initial_state=GaussianState([0, 0, 0, 0], np.diag([1, 1, 1, 1]), start),
        timestep=datetime.timedelta(seconds=1), number_steps=SCANS, birth_rate=0, death_probability=0,
        preexisting_states=starts, seed=seed)
    measurement = LinearGaussian(ndim_state=4, mapping=(0, 2), noise_covar=np.eye(2) * R)
    sensor = SimpleDetectionSimulator(groundtruth=truth, measurement_model=measurement,
                                      meas_range=np.array([[-1, 1], [-1, 1]]) * HALF_WIDTH,
                                      detection_probability=PD, clutter_rate=CLUTTER, seed=seed + 1000)
    scans = []
    for when, dets in sensor:
        paths = sensor.groundtruth.current[1]
        scans.append((when, sorted(dets, key=lambda d: tuple(np.ravel(d.state_vector))), np.array([[s.state_vector[0], s.state_vector[2]] for s in
                                                 (p[-1] for p in paths if p[-1].timestamp == when)]).reshape(-1, 2)))
    return scans, measurement, transition


def stone_soup(scans, measurement, transition) -> tuple[list[np.ndarray], int, float]:
    """Stone Soup's JPDA with EHM (its tutorial's set-up, with the simulation's own models): per-scan track
    positions, ids used, milliseconds per scan."""
    predictor, updater = KalmanPredictor(transition), KalmanUpdater(measurement)
    hypothesiser = PDAHypothesiser(predictor=predictor, updater=updater, clutter_spatial_density=DENSITY,
                                   prob_detect=PD)
    deleter = CovarianceBasedDeleter(covar_trace_thresh=DELETE_TRACE)
    initiator = MultiMeasurementInitiator(
        prior_state=GaussianState([0, 0, 0, 0], np.diag([R, 1.0, R, 1.0]) * 4),
        measurement_model=measurement, deleter=deleter, min_points=2, updater=updater,
        data_associator=GNNWith2DAssignment(DistanceHypothesiser(predictor, updater, Mahalanobis(), 3)))
    tracker = MultiTargetMixtureTracker(initiator=initiator, deleter=deleter, detector=iter(
        [(when, dets) for when, dets, _ in scans]), data_associator=JPDAwithEHM(hypothesiser), updater=updater)
    out, ids = [], set()
    tick = time.perf_counter()
    for when, tracks in tracker:
        live = [t for t in tracks if t.state.timestamp == when]
        ids |= {t.id for t in live}
        out.append(np.array([[t.state_vector[0], t.state_vector[2]] for t in live]).reshape(-1, 2))
    return out, len(ids), 1000 * (time.perf_counter() - tick) / len(scans)


def ours(spec: str, scans) -> tuple[list[np.ndarray], int, float]:
    """One of our trackers on the same detections, each a 2 x 2 box with confidence 1."""
    tracker = make(spec)
    tracker.reset()
    frames = []
    for _, dets, _ in scans:
        z = np.array([[float(d.state_vector[0]), float(d.state_vector[1])] for d in dets]).reshape(-1, 2)
        frames.append({"detections": np.c_[z - 1, np.full((len(z), 2), 2.0), np.ones(len(z))],
                       "num_detections": np.int64(len(z))})
    out, ids = [], set()
    tick = time.perf_counter()
    for obs in frames:
        tracks = tracker.update(obs)
        ids |= set(tracks.ids.tolist())
        out.append(tracks.boxes[:, :2] + tracks.boxes[:, 2:4] / 2)
    return out, len(ids), 1000 * (time.perf_counter() - tick) / len(scans)


def mean_gospa(estimates: list[np.ndarray], scans) -> float:
    return float(np.mean([gospa_of_points(truth, est, C, P) for est, (_, _, truth) in
                          list(zip(estimates, scans))[FROM_SCAN:]]))


def matched(spec: str) -> str:
    """jpda or gnn with the simulation's parameters, those given after the colon overriding them (any other spec
    as it is)."""
    name, _, extra = spec.partition(":")
    if name not in OURS:
        return spec
    params = dict(kv.split("=") for kv in (OURS[name].partition(":")[2] + "," + extra).strip(",").split(","))
    return name + ":" + ",".join(f"{k}={v}" for k, v in params.items())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--ours", default="jpda;gnn", help="';'-separated tracker specs; jpda and gnn take the "
                        "simulation's parameters, and any after a colon on top (jpda:coast=true)")
    args = parser.parse_args()
    specs = args.ours.split(";")
    rows = {name: [] for name in ["stonesoup JPDAwithEHM", *specs]}
    for seed in range(args.seeds):
        scans, measurement, transition = simulate(seed)
        runs = [stone_soup(scans, measurement, transition)] + [ours(matched(spec), scans) for spec in specs]
        for name, (est, ids, ms) in zip(rows, runs):
            rows[name].append((mean_gospa(est, scans), ids, ms))
            print(f"seed {seed}  {name:40s} GOSPA {rows[name][-1][0]:6.2f}  ids {ids:4d}  {ms:7.2f} ms/scan",
                  flush=True)
    print(f"\nmedians over {args.seeds} seeds ({TARGETS} targets, {SCANS} scans, P_D {PD}, {CLUTTER:g} clutter a scan)")
    print("| tracker | GOSPA | ids | ms/scan |\n|---|---:|---:|---:|")
    for name, runs in rows.items():
        gospa, ids, ms = (statistics.median(r[i] for r in runs) for i in range(3))
        print(f"| {name} | {gospa:.2f} | {ids:g} | {ms:.2f} |")


if __name__ == "__main__":
    main()

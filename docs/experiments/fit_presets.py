"""Fit the detector presets `dpm`, `frcnn` and `sdp` (mtt_sim/core/detectors/*.toml) to MOT17's public detectors.

What is published about them is one number each, the average precision on MOT17 (MOTChallenge's MOT17Det
benchmark: DPM 0.61, FRCNN 0.72, SDP 0.81). How a detector fails over time is not published, so every key but
its recall comes from `mot15_frcnn` (fitted by `mtt-sim calibrate` to the eight shared MOT15 sequences' Faster R-CNN
detections): a preset is that detector with P(detect) shifted by one number d on the logit scale, d found by
bisection so that the average precision over mot17_like's people (seeds 0 and 1, 600 frames) is the published one,
or as near as the shift can bring it (poor boxes, IoU 0.3 to 0.5 with the person, stay misses whatever d is).

    python docs/experiments/fit_presets.py          # writes mtt_sim/core/detectors/{dpm,frcnn,sdp}.toml, prints the fit
"""

import sys
from pathlib import Path

from scipy.special import expit, logit

from mtt_sim.sim2real import calibrate

from mtt_sim.sim import scenario

PUBLISHED_AP = {"dpm": 0.61, "frcnn": 0.72, "sdp": 0.81}
DETECTORS = Path(__file__).resolve().parents[2] / "mtt_sim" / "core" / "detectors"


def shifted(base: dict, d: float) -> dict:
    """mot15_frcnn with P(detect) shifted by d, its confidences spread over [0, 1] (the SORT files keep only scores
    above 0.5; MOT17's files keep low ones too, which ByteTrack's and lmb's second rounds use)."""
    return {**base, "pd": float(expit(logit(base["pd"]) + d)), "conf_offset": 0.0, "conf_scale": 1.0}


def mot17_like_ap(sensor: dict) -> float:
    """Average precision of the detector over every person of mot17_like (seeds 0 and 1 pooled)."""
    config = {"sensor": {**sensor, "preset": ""}}
    return calibrate.scenario_statistics("mot17_like", config, seeds=(0, 1))["average precision"]


def main():
    base = {k: v for k, v in scenario.PRESETS["mot15_frcnn"].items()}
    for name, target in PUBLISHED_AP.items():
        if sys.argv[1:] and name not in sys.argv[1:]:
            continue
        lo, hi = -4.0, 6.0
        for _ in range(12):
            mid = (lo + hi) / 2
            lo, hi = (mid, hi) if mot17_like_ap(shifted(base, mid)) < target else (lo, mid)
        d = (lo + hi) / 2
        keys = shifted(base, d)
        ap = mot17_like_ap(keys)
        print(f"{name}: d = {d:+.3f}, pd {keys['pd']:.4f}: average precision on mot17_like {ap:.3f} (published {target})")
        comments = [f"The {name.upper()} detector of MOT17 (average precision {target} on MOT17Det): mot15_frcnn with "
                    "P(detect) shifted by",
                    f"d = {d:+.3f} on the logit scale, so that its average precision over mot17_like's people is {ap:.3f},",
                    "and its confidences spread over [0, 1]. Written by docs/experiments/fit_presets.py."]
        rounded = {k: round(v, 4) if isinstance(v, float) else v for k, v in keys.items()}
        (DETECTORS / f"{name}.toml").write_text(calibrate.sensor_toml(rounded, comments))


if __name__ == "__main__":
    main()

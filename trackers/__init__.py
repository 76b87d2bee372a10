"""Tracker agents for mtt-sim, installed as `mtt_sim.trackers` (the top-level name `trackers` is Roboflow's): pure
numpy/scipy/OpenCV, never importing the simulator (only `mtt_sim.trackers.*`) or seeing ground truth.

    from mtt_sim import trackers
    trackers.available()                 # names with one-line descriptions
    t = trackers.make("sort", max_age=3) # or trackers.make("sort:max_age=3")
    t.reset(info); tracks = t.update(obs); env.step(tracks.to_action(env.action_space))
"""

from . import bytetrack, echo, gmphd, gnn, iou, ipf, jpda, learned, lmb, ocsort, particle, sort  # noqa: F401  (each registers its tracker)
from .base import Param, Tracker, Tracks, available, make, parse_spec, register, split_specs
from .external import External
from .roboflow import SupervisionTracker

__all__ = ["External", "SupervisionTracker", "Param", "Tracker", "Tracks",
           "available", "make", "parse_spec", "register", "split_specs"]

"""Tracker agents for mtt-sim, installed as `mtt_sim.trackers` (the top-level name `trackers` is Roboflow's): pure
numpy/scipy/OpenCV, never importing the simulator (only `mtt_sim.trackers.*`) or seeing ground truth.

    from mtt_sim import trackers
    trackers.available()                 # names with one-line descriptions
    t = trackers.make("sort", max_age=3) # or trackers.make("sort:max_age=3")
    t.reset(info); tracks = t.update(obs); env.step(tracks.to_action(env.action_space))

Three layers: `base.py` (the interface and the registry), `parts/` (what trackers are built from: filters,
association, the track table, camera motion, appearance), and one module per tracker that imports only those two;
`adapters/` runs trackers from elsewhere, and `registry.py` lists the built-in ones (docs/trackers_from_parts.md).
"""

from . import moved
from .adapters.external import External
from .adapters.roboflow import SupervisionTracker
from .base import Param, Tracker, TrackerSpec, Tracks, available, make, parse_spec, register, split_specs
from .registry import BUILT_IN

moved.install()
__getattr__ = moved.package_attribute

__all__ = ["BUILT_IN", "External", "SupervisionTracker", "Param", "Tracker", "TrackerSpec", "Tracks",
           "available", "make", "parse_spec", "register", "split_specs"]

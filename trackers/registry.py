"""The built-in trackers, listed once: `make("sort")` and `mtt-sim trackers` find them here. Installed plugins and
user classes join the same registry through `register` (base.py)."""

from .adapters.roboflow import RoboflowBotSort, RoboflowByteTrack, RoboflowOcSort, RoboflowSort
from .base import register
from .bytetrack import ByteTrack
from .echo import Echo
from .gmphd import GaussianMixturePhd
from .gnn import Gnn
from .iou import IouTracker
from .ipf import InteractiveParticleFilter, PathConsistencyParticleFilter
from .jpda import Jpda, JpdaExact
from .learned import Learned
from .lmb import LabelledMultiBernoulli
from .ocsort import OcSort
from .particle import ColourTextureParticleFilter
from .sort import Sort

BUILT_IN = (ByteTrack, Echo, GaussianMixturePhd, Gnn, IouTracker, InteractiveParticleFilter,
            PathConsistencyParticleFilter, Jpda, JpdaExact, Learned, LabelledMultiBernoulli, OcSort,
            ColourTextureParticleFilter, Sort, RoboflowSort, RoboflowByteTrack, RoboflowOcSort, RoboflowBotSort)

for tracker in BUILT_IN:
    register(tracker)

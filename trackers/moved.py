"""Import paths from before the trackers were layered into parts/ and adapters/ (issue 40), kept working as
deprecated aliases: `mtt_sim.trackers.kalman` is `mtt_sim.trackers.parts.kalman`, `mtt_sim.trackers.sort.SortTracks`
is `mtt_sim.trackers.parts.associations.SortAssociation`, and so on; each use warns with the new path."""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys
import warnings

PACKAGE = __name__.rpartition(".")[0]
MODULES = {name: f"parts.{name}" for name in ("appearance", "assignment", "camera_motion", "gaussian_mixture",
                                             "kalman", "management", "near_pairs", "reid")}
MODULES.update({name: f"adapters.{name}" for name in ("external", "roboflow")})
NAMES = {  # module: {old name: "new module:new name"}
    "sort": {"SortTracks": "parts.associations:SortAssociation", "associate": "parts.rounds:associate",
             "without": "parts.rounds:without", "paired_iou": "parts.assignment:paired_iou",
             "corners_to_measurement": "parts.boxes:corners_to_measurement",
             "state_to_corners": "parts.boxes:state_to_corners"},
    "bytetrack": {name: f"parts.boxes:{name}" for name in ("xyah_to_tlwh", "xyah_to_corners", "tlwh_to_xyah")},
    "ocsort": {"rematch": "parts.rounds:rematch"},
    "jpda": {"clusters": "parts.assignment:clusters"},
    "particle": {name: f"parts.particles:{name}" for name in ("initial_targets", "image_size", "crop_around",
                                                               "systematic_resample")},
    "parts.management": {"ByteTracks": "parts.associations:ByteAssociation"},
}


def _deprecated(old: str, new: str) -> None:
    warnings.warn(f"{old} is deprecated: use {new}", DeprecationWarning, stacklevel=3)


def _aliases(module: str, names: dict[str, str]):
    """A module's __getattr__ answering its old names from where they went."""
    def __getattr__(name: str):
        if name not in names:
            raise AttributeError(f"module {module!r} has no attribute {name!r}")
        where, _, new = names[name].partition(":")
        _deprecated(f"{module}.{name}", f"{PACKAGE}.{where}.{new}")
        return getattr(importlib.import_module(f"{PACKAGE}.{where}"), new)
    return __getattr__


class _MovedModules(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Finds `mtt_sim.trackers.<old>` as a module that hands on every name of the module it moved to."""

    def find_spec(self, fullname, path=None, target=None):
        package, _, old = fullname.rpartition(".")
        return importlib.util.spec_from_loader(fullname, self) if package == PACKAGE and old in MODULES else None

    def create_module(self, spec):
        return None

    def exec_module(self, module) -> None:
        new = f"{PACKAGE}.{MODULES[module.__name__.rpartition('.')[2]]}"
        _deprecated(module.__name__, new)
        target = importlib.import_module(new)
        module.__doc__ = f"Deprecated: moved to {new}."
        module.__getattr__ = lambda name: getattr(target, name)


def package_attribute(name: str):
    """The package's __getattr__: `mtt_sim.trackers.kalman` and the like, imported on first use."""
    if name not in MODULES:
        raise AttributeError(f"module {PACKAGE!r} has no attribute {name!r}")
    return importlib.import_module(f"{PACKAGE}.{name}")


def install() -> None:
    """Answer the old paths (once per process)."""
    if not any(isinstance(finder, _MovedModules) for finder in sys.meta_path):
        sys.meta_path.append(_MovedModules())
    for module, names in NAMES.items():
        importlib.import_module(f"{PACKAGE}.{module}").__getattr__ = _aliases(f"{PACKAGE}.{module}", names)

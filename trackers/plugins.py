"""Trackers from outside the package: a class named by module or file in a spec, and installed plugins.

A spec may name a `Tracker` subclass where it would name a registered tracker: `mypkg.mine:MyTracker` (a module on
the path, dotted, so it cannot be read as a registered name) or `./mine.py:MyTracker` (a file), each optionally
followed by `:key=value,...`. The spec is a string, so a
worker process (forked or spawned) loads the class again from it. Installed packages add trackers through the entry
point group `mtt_sim.trackers` (name = module:Class); they join the registry under the entry point's name.
"""

from __future__ import annotations

import hashlib
import importlib
import importlib.util
import sys
from importlib.metadata import entry_points
from pathlib import Path

ENTRY_POINT_GROUP = "mtt_sim.trackers"
_loaded_plugins = False


def is_location(name: str) -> bool:
    """Whether a spec's first part names a module or a file rather than a registered tracker."""
    return "." in name or "/" in name or "\\" in name


def load_class(location: str, class_name: str, base: type) -> type:
    """The `base` subclass `class_name` of module or file `location`, or a ValueError saying what is wrong."""
    where = f"tracker {location}:{class_name}"
    if location.endswith(".py") or "/" in location or "\\" in location:
        path = Path(location).resolve()
        if not path.is_file():
            raise ValueError(f"{where}: no such file {location!r} (a Python file defining the tracker class)")
        key = "mtt_sim_user_" + hashlib.sha1(str(path).encode()).hexdigest()[:12]
        module = sys.modules.get(key)
        if module is None:
            spec = importlib.util.spec_from_file_location(key, path)
            module = importlib.util.module_from_spec(spec)
            sys.modules[key] = module
            try:
                spec.loader.exec_module(module)
            except Exception:
                del sys.modules[key]
                raise
    else:
        try:
            module = importlib.import_module(location)
        except ModuleNotFoundError as err:
            raise ValueError(f"{where}: cannot import module {location!r} ({err})") from None
    cls = getattr(module, class_name, None)
    if not (isinstance(cls, type) and issubclass(cls, base)):
        found = "not found" if cls is None else f"a {type(cls).__name__}, not a subclass of mtt_sim.trackers.Tracker"
        raise ValueError(f"{where}: {class_name!r} in {location!r} is {found}")
    return cls


def load_plugins(register) -> None:
    """Register the trackers of installed packages' `mtt_sim.trackers` entry points, once."""
    global _loaded_plugins
    if _loaded_plugins:
        return
    _loaded_plugins = True
    for point in entry_points(group=ENTRY_POINT_GROUP):
        register(point.load(), point.name)

"""Deprecated aliases: a module whose public names moved below it keeps answering to them, with a warning."""

from __future__ import annotations

import warnings
from types import ModuleType
from typing import Callable


def moved(old: str, home: ModuleType, *names: str) -> Callable[[str], object]:
    """A module `__getattr__` for module `old` that hands on `names` from `home`, where they live now, with a
    DeprecationWarning that names the new place; any other name is missing as usual."""
    def __getattr__(name: str):
        if name not in names:
            raise AttributeError(f"module {old!r} has no attribute {name!r}")
        warnings.warn(f"{old}.{name} moved to {home.__name__}.{name}; import it from there", DeprecationWarning,
                      stacklevel=2)
        return getattr(home, name)

    return __getattr__

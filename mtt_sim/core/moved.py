"""Deprecated aliases: a module whose public names moved (or were renamed) keeps answering to them, with a warning."""

from __future__ import annotations

import importlib
import warnings
from types import ModuleType
from typing import Callable


def moved(old: str, home: ModuleType | str, *names: str, **renamed: str) -> Callable[[str], object]:
    """A module `__getattr__` for module `old` that hands on `names` (and each old name of `renamed`, as its new name)
    from `home`, where they live now (a module, or its name: imported at the first use), with a DeprecationWarning
    that names the new place; any other name is missing as usual."""
    targets = {**{name: name for name in names}, **renamed}

    def __getattr__(name: str):
        if name not in targets:
            raise AttributeError(f"module {old!r} has no attribute {name!r}")
        module = importlib.import_module(home) if isinstance(home, str) else home
        warnings.warn(f"{old}.{name} moved to {module.__name__}.{targets[name]}; import it from there",
                      DeprecationWarning, stacklevel=2)
        return getattr(module, targets[name])

    return __getattr__

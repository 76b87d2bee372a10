"""The validator of configuration tables: a nested mapping (TOML file, overrides) built into frozen dataclasses.

One generic validator walks the dataclasses of `mtt_sim.core.settings` and `mtt_sim.sim.config` (or any schema of
such tables, as a recorded sequence's) and rejects unknown keys, wrong types and out-of-range values with a message
naming the source, the dotted key, the value and what is allowed; it fills the sensor keys from a named preset. Both
sources build their configuration with it; `mtt_sim.sim.scenario` adds a scenario's cross-field rules and files.
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import typing
from typing import Any, Mapping

import numpy as np

from mtt_sim.core.settings import PRESETS, ConfigError

# ---------------------------------------------------------------- building from mappings

def _type_name(tp) -> str:
    return getattr(tp, "__name__", str(tp))


def _convert(value, tp, key: str, meta: Mapping, where: str):
    """Check `value` against annotation `tp` and the field's range/choices; return the typed value."""

    given = value

    def fail(allowed: str):
        raise ConfigError(f"{where}: {key} = {given!r}: {allowed}")

    if isinstance(value, (np.generic, np.ndarray)):  # numpy numbers and arrays are numbers and lists
        value = value.tolist()
    origin = typing.get_origin(tp)
    if dataclasses.is_dataclass(tp):
        if not isinstance(value, Mapping):
            fail(f"expected a table of {tp.__name__} keys")
        return _build(tp, value, where, key + ".")
    if origin is tuple:
        args = typing.get_args(tp)
        if not isinstance(value, (list, tuple)):
            fail(f"expected a list ({describe(tp)})")
        if len(args) == 2 and args[1] is Ellipsis:
            return tuple(_convert(v, args[0], f"{key}.{i}", meta, where) for i, v in enumerate(value))
        if len(value) != len(args):
            fail(f"expected {len(args)} values ({describe(tp)})")
        return tuple(_convert(v, a, f"{key}.{i}", meta, where) for i, (v, a) in enumerate(zip(value, args)))
    if tp is bool:
        if not isinstance(value, bool):
            fail("expected true or false")
        return value
    if tp is int:
        if isinstance(value, bool) or not isinstance(value, int):
            fail("expected an integer" + range_text(meta))
    elif tp is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(_as_float(value)):
            fail("expected a finite number" + range_text(meta))
        value = float(value)
    elif tp is str:
        if not isinstance(value, str):
            fail("expected a string")
    if meta.get("choices") is not None and value not in meta["choices"]:
        fail(f"allowed values: {', '.join(repr(c) for c in meta['choices'])}")
    lo, hi = meta.get("lo"), meta.get("hi")
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        fail("out of range" + range_text(meta))
    return value


def _as_float(value: int | float) -> float:
    """float(value), with an integer too large for a float read as infinite (so it fails as not finite)."""
    try:
        return float(value)
    except OverflowError:
        return math.inf


def range_text(meta: Mapping) -> str:
    lo, hi = meta.get("lo"), meta.get("hi")
    if lo is None and hi is None:
        return ""
    return f"; allowed: {'-inf' if lo is None else lo} <= value <= {'inf' if hi is None else hi}"


def describe(tp) -> str:
    if typing.get_origin(tp) is tuple:
        args = typing.get_args(tp)
        if len(args) == 2 and args[1] is Ellipsis:
            return f"list of {describe(args[0])}"
        return f"{len(args)} x {_type_name(args[0])}"
    return _type_name(tp)


_HINTS: dict[type, dict[str, Any]] = {}


def hints(cls) -> dict[str, Any]:
    if cls not in _HINTS:
        _HINTS[cls] = typing.get_type_hints(cls)
    return _HINTS[cls]


def _build(cls, raw: Mapping, where: str, prefix: str = ""):
    """Construct dataclass `cls` from mapping `raw`, validating every key."""
    fields = {f.name: f for f in dataclasses.fields(cls)}
    unknown = sorted(set(raw) - set(fields), key=str)
    if unknown:
        near = difflib.get_close_matches(str(unknown[0]), fields, n=1)
        raise ConfigError(f"{where}: unknown key {prefix}{unknown[0]}" + (f" (did you mean {prefix}{near[0]}?)" if near
                          else "") + f"; allowed keys: {', '.join(fields)}")
    types = hints(cls)
    values = {name: _convert(raw[name], types[name], prefix + name, fields[name].metadata, where)
              for name in fields if name in raw}
    return cls(**values)

def _with_preset(raw: Mapping, where: str) -> dict:
    """Fill sensor keys from the named preset under the explicitly given ones."""
    raw = dict(raw)
    sensor = raw.get("sensor")
    if isinstance(sensor, Mapping) and sensor.get("preset"):
        if sensor["preset"] not in PRESETS:
            raise ConfigError(f"{where}: sensor.preset = {sensor['preset']!r}: allowed values: {', '.join(map(repr, PRESETS))}")
        raw["sensor"] = {**PRESETS[sensor["preset"]], **sensor}
    return raw


def build(raw: Mapping, where: str, schema: type):
    """Build and validate `schema` (a dataclass of configuration tables) from a nested mapping (as read from TOML),
    the sensor keys filled from their preset."""
    if not isinstance(raw, Mapping):
        raise ConfigError(f"{where}: expected a table of scenario keys, got {type(raw).__name__}")
    return _build(schema, _with_preset(raw, where), where)


# ---------------------------------------------------------------- overrides


def expand_dotted(overrides: Mapping, prefix: str = "") -> dict:
    """Turn {"sensor.pd": 0.5} and nested dicts alike, or any mix of the two, into one nested dict.

    Integer keys are list indices ({"groups": {0: {...}}} is "groups.0..."). A value given twice (say as
    "sensor.pd" and inside "sensor") is an error, never silently dropped.
    """
    if not isinstance(overrides, Mapping):
        raise ConfigError(f"config overrides must be a mapping of keys to values, got {type(overrides).__name__}")
    out: dict = {}
    for key, value in overrides.items():
        if isinstance(key, int) and not isinstance(key, bool):
            key = str(key)
        if not isinstance(key, str) or not key or "" in key.split("."):
            raise ConfigError(f"override key {prefix}{key!r}: keys are dotted names such as 'sensor.pd'")
        node, path = out, prefix
        *parents, leaf = key.split(".")
        for part in parents:
            path += part + "."
            node = node.setdefault(part, {})
            if not isinstance(node, dict):
                raise ConfigError(f"override {path.rstrip('.')} is given both as a value and as a table of keys")
        if isinstance(value, Mapping):
            value = expand_dotted(value, f"{path}{leaf}.")
        _put(node, leaf, value, path)
    return out


def _put(node: dict, key: str, value, prefix: str) -> None:
    """node[key] = value, merging tables and refusing a second value for the same key."""
    if key not in node:
        node[key] = value
    elif isinstance(node[key], dict) and isinstance(value, dict):
        for k, v in value.items():
            _put(node[key], k, v, f"{prefix}{key}.")
    else:
        raise ConfigError(f"override {prefix}{key} is given twice (e.g. as a dotted key and inside a table); give it once")


def merge(base: Mapping, overrides: Mapping, prefix: str = "") -> dict:
    """Recursively merge `overrides` into `base`; list items are addressed by index ("groups.0.count",
    "groups.0.size.0")."""
    out = dict(base)
    for key, value in overrides.items():
        out[key] = _merged(out.get(key), value, f"{prefix}{key}")
    return out


def _merged(current, value, path: str):
    if isinstance(current, Mapping) and isinstance(value, Mapping):
        return merge(current, value, path + ".")
    if isinstance(current, (list, tuple)) and isinstance(value, Mapping):
        items = list(current)
        for idx, sub in value.items():
            if not (isinstance(idx, str) and idx.isdigit() and int(idx) < len(items)):
                raise ConfigError(f"override {path}.{idx}: no such item; {path} has {len(items)} entries")
            items[int(idx)] = _merged(items[int(idx)], sub, f"{path}.{idx}")
        return items
    return value


def to_mapping(obj) -> Any:
    """A Scenario (or part) as plain nested dicts and lists, the inverse of `from_mapping`."""
    if dataclasses.is_dataclass(obj):
        return {f.name: to_mapping(getattr(obj, f.name)) for f in dataclasses.fields(obj)}
    if isinstance(obj, tuple):
        return [to_mapping(x) for x in obj]
    return obj

"""Scenarios: a nested mapping (TOML file, shipped key, overrides) validated into a frozen `Scenario`.

The generic validator (`mtt_sim.core.validate`) walks the dataclasses of `mtt_sim.sim.config` and rejects unknown
keys, wrong types and out-of-range values; here are a scenario's cross-field rules, its files and overrides, and the
configuration reference (`reference_table`) the same metadata generates.
"""

from __future__ import annotations

import dataclasses
import difflib
import functools
import json
import tomllib
import typing
from importlib import resources
from pathlib import Path
from typing import Mapping, Sequence

from mtt_sim.core.settings import PRESETS, ConfigError, EnvConfig, ScoringConfig, SensorConfig
from mtt_sim.core.validate import build, describe, expand_dotted, hints, merge, range_text, to_mapping
from mtt_sim.sim.config import DoorConfig, GroupConfig, OccluderConfig, RenderConfig, Scenario, WorldConfig


def setting_of(key: str) -> tuple[type, Mapping]:
    """The type (bool, int, float or str) and metadata (doc, unit, lo, hi, choices) of the single value a dotted key
    names, e.g. 'sensor.pd', 'groups.0.count' or 'groups.0.size.1'; a ConfigError naming the key otherwise."""
    tp, meta, path = Scenario, {}, ""
    for part in key.split("."):
        if dataclasses.is_dataclass(tp):
            fields = {f.name: f for f in dataclasses.fields(tp)}
            if part not in fields:
                raise ConfigError(f"{key}: no key {path}{part}; allowed: {', '.join(path + f for f in fields)}")
            tp, meta = hints(tp)[part], fields[part].metadata
        elif typing.get_origin(tp) is tuple:
            args = typing.get_args(tp)
            if not part.isdigit() or (args[-1] is not Ellipsis and int(part) >= len(args)):
                raise ConfigError(f"{key}: {path.rstrip('.')} is a list: expected an item's index, got {part!r}")
            tp = args[0] if args[-1] is Ellipsis else args[int(part)]
        else:
            raise ConfigError(f"{key}: {path.rstrip('.')} is a single value, it has no {part!r}")
        path += part + "."
    if tp not in (bool, int, float, str):
        raise ConfigError(f"{key} is a table or a list ({describe(tp) if not dataclasses.is_dataclass(tp) else 'a table'}):"
                          " name one of its values")
    return tp, meta


def _check_references(sc: Scenario, where: str) -> Scenario:
    """Cross-field rules that a single field's range cannot express."""
    names = [g.name for g in sc.groups]
    if len(set(names)) != len(names):
        raise ConfigError(f"{where}: groups: names must be unique, got {names}")
    if not sc.groups:
        raise ConfigError(f"{where}: groups: at least one [[groups]] table is required")
    for i, g in enumerate(sc.groups):
        if g.motion == "carried":
            if g.carrier not in names or g.carrier == g.name:
                raise ConfigError(f"{where}: groups.{i}.carrier = {g.carrier!r}: must name another group, one of {names}")
            if g.birth_rate > 0:
                raise ConfigError(f"{where}: groups.{i}.birth_rate: carried targets are only placed at reset")
        x0, y0, x1, y1 = g.region
        if x1 <= x0 or y1 <= y0:
            raise ConfigError(f"{where}: groups.{i}.region = {g.region}: need x0 < x1 and y0 < y1")
    for i, d in enumerate(sc.doors):
        if d.group and d.group not in names:
            raise ConfigError(f"{where}: doors.{i}.group = {d.group!r}: allowed values: {names}")
    ww, wh = sc.world_size
    if ww < sc.render.width or wh < sc.render.height:
        raise ConfigError(f"{where}: world.size = {sc.world.size}: must be at least the image size "
                          f"({sc.render.width}, {sc.render.height}) or 0")
    if sc.sensor.model == "foreground" and sc.render.camera in ("pan", "follow"):
        raise ConfigError(f"{where}: sensor.model = 'foreground' needs a static or shaking camera, not render.camera = "
                          f"{sc.render.camera!r}")
    if sc.render.camera_forward > 0 and (sc.world.projection != "standing" or sc.world.far_scale >= 1.0):
        raise ConfigError(f"{where}: render.camera_forward = {sc.render.camera_forward:g} needs a ground in perspective: "
                          f"world.projection = 'standing' and world.far_scale < 1, not {sc.world.projection!r} and "
                          f"{sc.world.far_scale:g}")
    if sc.render.camera_companions and not sc.render.camera_forward:
        raise ConfigError(f"{where}: render.camera_companions = {sc.render.camera_companions}: people walk with a "
                          "camera going forward; set render.camera_forward > 0 or the companions to 0")
    return _check_budget(sc, where)


LABEL_MAX = 65535  # the uint16 label map holds slot + 1 of every target alive
MEMORY_BUDGET = 4 * 2**30  # bytes; a scenario estimated to need more is refused before anything is allocated


def memory_estimate(sc: Scenario) -> int:
    """Bytes an episode of `sc` needs at its peak, roughly: the world backdrop (about 100 bytes a pixel while its
    noise is made in float64, 3 once done), each image pixel's frame, label map, noise bank and detector model
    (40 bytes), and each target's arrays and pymunk body (2 KB)."""
    ww, wh = sc.world_size
    margin = 8 * sc.render.shake if sc.render.camera == "shake" else 0.0
    world_px = (ww + margin) * (wh + margin)
    image_px = sc.render.width * sc.render.height
    per_world_px = 3 if sc.render.background == "flat" else 100
    return int(world_px * per_world_px + image_px * 40 + sum(g.count for g in sc.groups) * 2048)


def _check_budget(sc: Scenario, where: str) -> Scenario:
    """Totals no single field's range bounds: targets against the label map's range, the memory an episode needs."""
    total = sum(g.count for g in sc.groups)
    if total > LABEL_MAX:
        counts = " + ".join(str(g.count) for g in sc.groups)
        raise ConfigError(f"{where}: groups[].count: {counts} = {total} targets at reset; at most {LABEL_MAX} can be "
                          "alive at once (the uint16 label map's range)")
    need = memory_estimate(sc)
    if need > MEMORY_BUDGET:
        ww, wh = sc.world_size
        raise ConfigError(f"{where}: this scenario would need about {need / 2**30:.1f} GiB (world.size {ww:g} x {wh:g} "
                          f"px, image {sc.render.width} x {sc.render.height} px, {total} targets); the budget is "
                          f"{MEMORY_BUDGET / 2**30:.0f} GiB: make the world or the image smaller")
    return sc


def from_mapping(raw: Mapping, where: str = "<config>", schema: type = Scenario):
    """Build and validate a Scenario (or another schema of configuration tables, such as a recorded sequence's) from a
    nested mapping (as read from TOML)."""
    built = build(raw, where, schema)
    return _check_references(built, where) if schema is Scenario else built


# ---------------------------------------------------------------- files and overrides

def scenario_dir():
    """The folder of shipped scenario files: package data `mtt_sim.scenarios`, or `scenarios/` in a source checkout."""
    try:
        return resources.files("mtt_sim.scenarios")
    except ModuleNotFoundError:
        return Path(__file__).resolve().parents[2] / "scenarios"


def available() -> dict[str, str]:
    """Shipped scenario keys (file stems) mapped to the first sentence of their description."""
    out = {}
    for entry in sorted(scenario_dir().iterdir(), key=lambda p: p.name):
        if entry.name.endswith(".toml"):
            desc = load_raw(entry.name[:-5])[0].get("description", "")
            out[entry.name[:-5]] = desc.split(". ")[0].strip().rstrip(".")
    return out


@functools.cache
def shipped_names() -> dict[str, str]:
    """Shipped scenario keys mapped to their CamelCase names (the env id of key k is mtt_sim/<name>-v0)."""
    return {p.name[:-5]: tomllib.loads(p.read_text()).get("name", "Custom")
            for p in sorted(scenario_dir().iterdir(), key=lambda p: p.name) if p.name.endswith(".toml")}


def resolve(name: str | Path) -> str | Path:
    """The shipped key a user means, in any letter case or as its env id ("mtt_sim/Crossing-v0"); a .toml file is
    returned as a Path. An unknown name gets the list of keys and, for a near miss, a suggestion."""
    if isinstance(name, Path) or str(name).endswith(".toml"):
        if not Path(name).is_file():
            raise ConfigError(f"scenario file {str(name)!r}: not found")
        return Path(name)
    keys = shipped_names()
    spellings = {k.lower(): k for k in keys} | {f"mtt_sim/{n}-v0".lower(): k for k, n in keys.items()}
    typed = str(name).strip().lower()
    if typed in spellings:
        return spellings[typed]
    near = difflib.get_close_matches(typed, spellings, n=1, cutoff=0.7)
    raise ConfigError(f"unknown scenario {str(name)!r}" + (f" (did you mean {spellings[near[0]]!r}?)" if near else "")
                      + f"; available: {', '.join(keys)} (in any case, or their env ids, a .toml file or a sequence folder)")


def load_raw(key_or_path: str | Path, seen: tuple[str, ...] = ()) -> tuple[dict, str]:
    """Read a scenario's TOML mapping by shipped key (see `resolve`) or file path; returns (mapping, where).
    A file with `base = "<scenario>"` is that scenario's mapping with the file's keys merged over it (a variant)."""
    found = resolve(key_or_path)
    if isinstance(found, Path):
        text, where = found.read_text(), str(found)
    else:
        text, where = (scenario_dir() / f"{found}.toml").read_text(), f"scenarios/{found}.toml"
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise ConfigError(f"{where}: invalid TOML: {err}") from None
    if isinstance(found, Path):
        _anchor_trace(raw, found.parent)
    if "base" not in raw:
        return raw, where
    base = raw.pop("base")
    if not isinstance(base, str) or base in seen:
        raise ConfigError(f"{where}: base = {base!r}: expected the name of another scenario, without a cycle")
    try:
        return merge(load_raw(base, (*seen, str(found)))[0], raw), where
    except ConfigError as err:
        raise ConfigError(f"{where}: base = {base!r}: {err}") from None


def _anchor_trace(raw: dict, folder: Path) -> None:
    """A scenario file's relative render.trace (a camera-motion file) is relative to the file's folder."""
    render = raw.get("render")
    trace = render.get("trace") if isinstance(render, dict) else None
    if isinstance(trace, str) and trace and not Path(trace).is_absolute():
        render["trace"] = str(folder / trace)


def load(key_or_path: str | Path | Scenario, overrides: Mapping | None = None) -> Scenario:
    """Load a shipped scenario (by key), a TOML file or an existing Scenario, with optional overrides."""
    if isinstance(key_or_path, Scenario):
        raw, where = to_mapping(key_or_path), f"scenario {key_or_path.name}"
    else:
        raw, where = load_raw(key_or_path)
    return from_raw(raw, where, overrides)


def from_raw(raw: Mapping, where: str, overrides: Mapping | None = None) -> Scenario:
    """The scenario of a mapping `load_raw` read (from `where`), with optional overrides: `load` without the file read,
    for a source that is opened again and again (`mtt_sim.sources.SourceSpec`)."""
    if overrides:
        if not isinstance(overrides, Mapping):
            raise ConfigError(f"config overrides must be a mapping, got {type(overrides).__name__}")
        try:
            raw = merge(raw, expand_dotted(overrides))
        except ConfigError as err:
            raise ConfigError(f"{where}: {err}") from None
        where += " (with overrides)"
    sc = from_mapping(raw, where)
    if sc.sensor.model == "recorded":
        raise ConfigError(f"{where}: sensor.model = 'recorded' replays a sequence folder's det/det.txt; a scenario's "
                          "detector is 'synthetic' or 'foreground'")
    return sc


def toml_scalar(value) -> str:
    """A bool, string, int or float as TOML text (floats exactly, as repr writes them)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)  # JSON's string escapes are TOML's
    return str(value) if isinstance(value, int) else repr(float(value))


def to_toml(mapping: Mapping, comments: Sequence[str] = ()) -> str:
    """A mapping as TOML text after a comment header: its plain keys (scalars, lists of scalars), then its tables,
    then its arrays of tables ([[groups]]); one level deep, what scenarios, sensor files and tuning results need."""
    def table(items: Mapping) -> str:
        return "".join(f"{k} = " + (f"[{', '.join(map(toml_scalar, v))}]" if isinstance(v, (list, tuple))
                                    else toml_scalar(v)) + "\n" for k, v in items.items())

    def tables(v) -> bool:
        return isinstance(v, (list, tuple)) and bool(v) and all(isinstance(t, Mapping) for t in v)

    text = "".join(f"# {line}\n" for line in comments)
    plain = {k: v for k, v in mapping.items() if not isinstance(v, Mapping) and not tables(v)}
    parts = [table(plain)] if plain else []
    parts += [f"[{k}]\n" + table(v) for k, v in mapping.items() if isinstance(v, Mapping)]
    parts += [f"[[{k}]]\n" + table(t) for k, v in mapping.items() if tables(v) for t in v]
    return text + "\n".join(parts)


def read_sensor(path: str | Path) -> dict:
    """The [sensor] table of a TOML file (as `mtt-sim calibrate` writes), to be merged into a scenario's overrides."""
    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"{path}: no such sensor file (a TOML file with a [sensor] table, e.g. from mtt-sim calibrate)")
    try:
        table = tomllib.loads(path.read_text()).get("sensor")
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as err:
        raise ConfigError(f"{path}: invalid TOML: {err}") from None
    if not isinstance(table, Mapping):
        raise ConfigError(f"{path}: expected a [sensor] table")
    return {"sensor": dict(table)}


def reference_table() -> str:
    """Markdown table of every configuration key: key, default, unit, allowed values, meaning."""
    rows = ["| key | default | unit | allowed | meaning |", "|---|---|---|---|---|"]

    def walk(cls, prefix):
        types = hints(cls)
        for f in dataclasses.fields(cls):
            tp, meta = types[f.name], f.metadata
            inner = typing.get_args(tp)[0] if typing.get_origin(tp) is tuple else None
            if dataclasses.is_dataclass(tp):
                walk(tp, prefix + f.name + ".")
                continue
            if inner is not None and dataclasses.is_dataclass(inner):
                walk(inner, f"{prefix}{f.name}[].")
                continue
            default = f.default if f.default is not dataclasses.MISSING else f.default_factory()
            if meta.get("choices"):
                allowed = ", ".join(repr(c) for c in meta["choices"])
            else:
                allowed = range_text(meta).replace("; allowed: ", "")
            rows.append(f"| `{prefix}{f.name}` | `{default!r}` | {meta.get('unit', '')} | {allowed} | {meta.get('doc', '')} |")

    walk(Scenario, "")
    rows += ["", f"Totals: at most {LABEL_MAX} targets at reset (the sum of `groups[].count`, the uint16 label map's "
                 f"range), and an estimated peak memory (`mtt_sim.sim.scenario.memory_estimate`) of at most "
                 f"{MEMORY_BUDGET // 2**30} GiB, which bounds `world.size` times the image size."]
    return "\n".join(rows)


__all__ = ["Scenario", "GroupConfig", "DoorConfig", "OccluderConfig", "WorldConfig", "RenderConfig", "SensorConfig",
           "EnvConfig", "ScoringConfig", "ConfigError", "PRESETS", "available", "load", "load_raw", "from_mapping", "to_mapping",
           "merge", "expand_dotted", "reference_table", "resolve", "shipped_names"]


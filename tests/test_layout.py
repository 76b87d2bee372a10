"""The package's shape: data flows one way (no module imports one that imports it back, lazy imports included), the
trackers never import the simulator, a tracker imports only the base and the parts (never another tracker), the
recorded source never imports the simulator (their shared types live below both), no module is over 500 lines, and
`import trackers` is not this project."""

import ast
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
FOLDERS = {"mtt_sim": ROOT / "mtt_sim", "mtt_sim.trackers": ROOT / "trackers"}


def modules() -> dict[str, Path]:
    """Every module of the package by its dotted name (a package by its own name)."""
    out = {}
    for prefix, folder in FOLDERS.items():
        for path in folder.rglob("*.py"):
            parts = path.relative_to(folder).with_suffix("").parts
            parts = parts[:-1] if parts[-1] == "__init__" else parts
            out[".".join((prefix, *parts))] = path
    return out


def imports(name: str, path: Path, known: set[str]) -> set[str]:
    """The package's modules that `name` imports anywhere in its file (inside functions too), relative imports
    resolved; `from a import b` counts as importing a.b where that is a module, else a."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join(anchor + ([base] if base else []))
            targets = [f"{base}.{alias.name}" if f"{base}.{alias.name}" in known else base for alias in node.names]
        else:
            continue
        found |= {t for t in targets if t in known}
    return found - {name}


def graph() -> dict[str, set[str]]:
    found = modules()
    return {name: imports(name, path, set(found)) for name, path in found.items()}


def cycles(edges: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components with more than one module (Tarjan's algorithm)."""
    index, low, stack, on, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(edges.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                out.append(sorted(component))

    for v in sorted(edges):
        if v not in index:
            visit(v)
    return out


def test_the_cycle_finder_finds_a_planted_circle():
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert cycles({"a": {"b"}, "b": set()}) == []


def test_the_import_parser_sees_lazy_and_relative_imports(tmp_path):
    path = tmp_path / "m.py"
    path.write_text("from .base import x\n\ndef f():\n    from mtt_sim.sim import world\n")
    known = {"mtt_sim.trackers.base", "mtt_sim.sim", "mtt_sim.sim.world"}
    assert imports("mtt_sim.trackers.m", path, known) == {"mtt_sim.trackers.base", "mtt_sim.sim.world"}


def test_no_module_imports_one_that_imports_it_back():
    assert cycles(graph()) == []


def test_the_trackers_never_import_the_simulator():
    for name, targets in graph().items():
        if name.startswith("mtt_sim.trackers"):
            outside = sorted(t for t in targets if not t.startswith("mtt_sim.trackers"))
            assert not outside, f"{name} imports {outside}"


def layer_breaks(edges: dict[str, set[str]], tracker_modules: set[str]) -> list[str]:
    """The imports that break the trackers' layers: a module defining a tracker imports nothing but the base, the
    parts and the adapters' helpers (modules defining no tracker); a part imports nothing but parts and the base."""
    base, parts = "mtt_sim.trackers.base", "mtt_sim.trackers.parts"
    out = []
    for name, targets in sorted(edges.items()):
        if name in tracker_modules:
            allowed = lambda t: t == base or t.startswith(parts) or (t.startswith("mtt_sim.trackers.adapters")
                                                                      and t not in tracker_modules)
        elif name.startswith(parts):
            allowed = lambda t: t == base or t.startswith(parts)
        else:
            continue
        out += [f"{name} imports {t}" for t in sorted(targets) if not allowed(t)]
    return out


def test_the_layer_check_finds_a_tracker_importing_another_and_a_part_importing_a_tracker():
    edges = {"mtt_sim.trackers.ocsort": {"mtt_sim.trackers.sort", "mtt_sim.trackers.parts.rounds"},
             "mtt_sim.trackers.sort": {"mtt_sim.trackers.base", "mtt_sim.sim.world"},
             "mtt_sim.trackers.parts.management": {"mtt_sim.trackers.parts.kalman", "mtt_sim.trackers.bytetrack"}}
    trackers = {"mtt_sim.trackers.ocsort", "mtt_sim.trackers.sort", "mtt_sim.trackers.bytetrack"}
    assert layer_breaks(edges, trackers) == ["mtt_sim.trackers.ocsort imports mtt_sim.trackers.sort",
                                             "mtt_sim.trackers.parts.management imports mtt_sim.trackers.bytetrack",
                                             "mtt_sim.trackers.sort imports mtt_sim.sim.world"]


def test_a_tracker_imports_only_the_base_and_the_parts():
    from mtt_sim.trackers.registry import BUILT_IN
    tracker_modules = {cls.__module__ for cls in BUILT_IN}
    assert {"mtt_sim.trackers.sort", "mtt_sim.trackers.adapters.roboflow"} <= tracker_modules
    assert layer_breaks(graph(), tracker_modules) == []


def test_the_recorded_source_never_imports_the_simulator():
    for name, targets in graph().items():
        if name.startswith("mtt_sim.real"):
            simulator = sorted(t for t in targets if t == "mtt_sim.sim" or t.startswith("mtt_sim.sim."))
            assert not simulator, f"{name} imports {simulator}"


def test_the_names_that_moved_below_both_sources_keep_their_old_paths_with_a_warning():
    from mtt_sim.core import settings
    from mtt_sim.sim import config, truth

    with pytest.warns(DeprecationWarning, match="mtt_sim.core.settings.ConfigError"):
        assert config.ConfigError is settings.ConfigError
    with pytest.warns(DeprecationWarning, match="mtt_sim.boxes.occlusion_visibility"):
        from mtt_sim.sim.truth import occlusion_visibility  # noqa: F401
    with pytest.raises(AttributeError):
        truth.no_such_name
    from mtt_sim import cli
    from mtt_sim.metrics import PRINTED

    with pytest.warns(DeprecationWarning, match="mtt_sim.metrics.PRINTED"):
        assert cli.SUMMARY_KEYS == PRINTED


@pytest.mark.parametrize("name", sorted(modules()))
def test_no_module_is_over_500_lines(name):
    lines = len(modules()[name].read_text().splitlines())
    assert lines <= 500, f"{modules()[name].relative_to(ROOT)}: {lines} lines; split it by idea"


def test_import_trackers_does_not_find_this_project(tmp_path):
    code = "import importlib.util, mtt_sim.trackers as t; s = importlib.util.find_spec('trackers'); print(t.__name__, s)"
    done = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, check=True)
    name, spec = done.stdout.split(" ", 1)
    assert name == "mtt_sim.trackers"
    assert spec.strip() == "None" or str(ROOT / "trackers") not in spec


def test_old_import_paths_still_work_and_warn(monkeypatch):
    import importlib

    from mtt_sim.trackers.parts import associations, kalman
    monkeypatch.delitem(sys.modules, "mtt_sim.trackers.kalman", raising=False)
    with pytest.warns(DeprecationWarning, match="mtt_sim.trackers.parts.kalman"):
        old = importlib.import_module("mtt_sim.trackers.kalman")
    assert old.box_model is kalman.box_model
    sort = importlib.import_module("mtt_sim.trackers.sort")
    with pytest.warns(DeprecationWarning, match="SortAssociation"):
        assert sort.SortTracks is associations.SortAssociation
    with pytest.raises(AttributeError):
        sort.NoSuchName

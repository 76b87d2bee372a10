"""The package users install is the package tested: the wheel built from this tree holds every folder of Python files
under mtt_sim/, trackers/ and scenarios/ (the last two as mtt_sim.trackers and mtt_sim.scenarios), the data files the
code reads, and nothing at the top level but mtt_sim. A package left out of a hand-made list once broke the installed
`mtt-sim calibrate` while every test of the editable install passed."""

from __future__ import annotations

import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
INSTALLED_AS = {"mtt_sim": "mtt_sim", "trackers": "mtt_sim/trackers", "scenarios": "mtt_sim/scenarios"}  # folder: in the wheel
DATA = {"scenarios": "*.toml", "mtt_sim/core/detectors": "*.toml", "trackers/data": "*.npz"}  # read by the code at run time
NOT_SOURCE = (".git", ".venv", "build", "dist", "__pycache__", ".pytest_cache", ".hypothesis")


def source_files() -> list[str]:
    """The tree's files as `pip install .` sees them: git's tracked and untracked-but-not-ignored files in a checkout,
    else every file outside build outputs and caches."""
    if (ROOT / ".git").exists() and shutil.which("git"):
        listed = subprocess.run(["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"], cwd=ROOT,
                                capture_output=True, check=True).stdout.decode().split("\0")
        return sorted({name for name in listed if name and (ROOT / name).is_file()})
    return sorted(str(p.relative_to(ROOT)) for p in ROOT.rglob("*") if p.is_file()
                  and not any(part in NOT_SOURCE or part.endswith(".egg-info") for part in p.relative_to(ROOT).parts))


def setuptools_at_least(major: int) -> bool:
    try:
        import setuptools
    except ImportError:
        return False
    return int(setuptools.__version__.split(".")[0]) >= major


def in_wheel(path: str) -> str:
    """Where the source file `path` (relative to the root) lands in the wheel."""
    top, _, rest = path.partition("/")
    return f"{INSTALLED_AS[top]}/{rest}"


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> dict[str, bytes]:
    """The names in the wheel built from a copy of this tree (a copy: no build/ of an earlier build leaks in, and the
    checkout is left as it was)."""
    tmp = tmp_path_factory.mktemp("wheel")
    src, out = tmp / "src", tmp / "out"
    for name in source_files():
        (src / name).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(ROOT / name, src / name)
    # Without build isolation when the [test] extra's setuptools is here: offline and quick; else pip fetches one.
    isolation = ["--no-build-isolation"] if setuptools_at_least(77) else []
    done = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--quiet", *isolation, "-w", str(out),
                           str(src)], cwd=tmp, capture_output=True, text=True)
    assert done.returncode == 0, f"pip wheel failed:\n{done.stdout[-3000:]}\n{done.stderr[-3000:]}"
    wheels = list(out.glob("*.whl"))
    assert len(wheels) == 1, wheels
    with zipfile.ZipFile(wheels[0]) as z:
        return {name: z.read(name) for name in z.namelist()}


def test_every_folder_of_python_files_is_in_the_wheel(wheel):
    python = [name for name in source_files() if name.endswith(".py") and name.split("/")[0] in INSTALLED_AS]
    assert {name.split("/")[0] for name in python} == set(INSTALLED_AS)  # the listing itself works
    folders = sorted({str(Path(in_wheel(name)).parent) for name in python})
    held = {str(Path(name).parent) for name in wheel}
    assert [f for f in folders if f not in held] == [], "folders of Python files missing from the wheel"
    assert [in_wheel(name) for name in python if in_wheel(name) not in wheel] == [], "Python files missing from the wheel"


def test_the_data_files_are_in_the_wheel(wheel):
    for folder, pattern in DATA.items():
        files = sorted(str(p.relative_to(ROOT)) for p in (ROOT / folder).glob(pattern))
        assert files, f"no {pattern} in {folder}/: the test's list of data files is out of date"
        assert [in_wheel(name) for name in files if in_wheel(name) not in wheel] == [], f"{folder}/{pattern} left out"


def test_the_wheel_installs_only_mtt_sim_and_its_command(wheel):
    tops = {name.split("/")[0] for name in wheel}
    info = {t for t in tops if t.endswith(".dist-info")}
    assert tops - info == {"mtt_sim"}, "only mtt_sim at the top level (`trackers` is Roboflow's name)"
    (info,) = info
    assert "mtt-sim = mtt_sim.cli:main" in wheel[f"{info}/entry_points.txt"].decode()  # the README's first command

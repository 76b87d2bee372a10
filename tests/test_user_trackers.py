"""A user's own tracker in every command: named by file or module in a spec, or installed as a plugin."""

import textwrap

import pytest
from mtt_sim.trackers import plugins

from mtt_sim import trackers
from mtt_sim.cli import main

MINE = textwrap.dedent('''
    import numpy as np
    from mtt_sim.trackers import Param, Tracker, Tracks
    from mtt_sim.trackers.base import detections


    class Mine(Tracker):
        """Each confident detection as a track, numbered by its row."""
        name = "mine"
        description = "confident detections as tracks"
        parameters = {"min_confidence": Param(0.5, "[0, 1]", "detections below are dropped", (0.0, 0.9))}

        def update(self, obs):
            d = detections(obs)
            d = d[d[:, 4] >= self.params["min_confidence"]]
            return Tracks.of(np.arange(1, len(d) + 1), d[:, :4])


    not_a_tracker = 3
''')


@pytest.fixture
def tracker_file(tmp_path, monkeypatch):
    (tmp_path / "mine.py").write_text(MINE)
    monkeypatch.chdir(tmp_path)
    return "./mine.py:Mine"


def test_a_tracker_file_runs_in_run_bench_with_spawned_workers_sweep_and_tune(tracker_file, capsys):
    assert main(["trackers", tracker_file]) == 0
    assert "min_confidence=0.5" in capsys.readouterr().out
    short = ["--config", "env.max_steps=20"]
    assert main(["run", "crossing", "--tracker", f"{tracker_file}:min_confidence=0.3", "--json", *short]) == 0
    assert '"MOTA"' in capsys.readouterr().out
    assert main(["bench", "--scenarios", "crossing", "--trackers", f"{tracker_file};sort", "--seeds", "2",
                 "--workers", "2", *short]) == 0  # the pool's workers are spawned: they load the file themselves
    assert "| ./mine.py:Mine |" in capsys.readouterr().out
    assert main(["sweep", "crossing", "--param", "sensor.clutter_rate=0,5", "--trackers", tracker_file,
                 "--seeds", "1", *short]) == 0
    assert main(["tune", tracker_file, "--on", "crossing", "--trials", "2", "--json", *short]) == 0
    assert '"spec": "./mine.py:Mine:min_confidence=0.5"' in capsys.readouterr().out


def test_a_tracker_file_is_checked_like_ours(tracker_file):
    assert trackers.parse_spec(f"{tracker_file}:min_confidence=0.2") == (tracker_file, {"min_confidence": "0.2"})
    assert trackers.make(tracker_file).params == {"min_confidence": 0.5}
    with pytest.raises(ValueError, match=r"tracker 'mine': parameter min_confidence='2': allowed: a number in \[0, 1\]"):
        trackers.make(f"{tracker_file}:min_confidence=2")
    with pytest.raises(ValueError, match=r"no such file './other.py'"):
        trackers.make("./other.py:Mine")
    with pytest.raises(ValueError, match=r"'not_a_tracker' in './mine.py' is a int, not a subclass"):
        trackers.make("./mine.py:not_a_tracker")
    with pytest.raises(ValueError, match=r"'Missing' in './mine.py' is not found"):
        trackers.make("./mine.py:Missing")
    with pytest.raises(ValueError, match="cannot import module 'no_such_pkg.mod'"):
        trackers.make("no_such_pkg.mod:Mine")


def test_a_module_tracker_and_an_installed_plugin(tmp_path, monkeypatch):
    monkeypatch.setattr(plugins, "_loaded_plugins", False)
    monkeypatch.setattr(trackers.base, "REGISTRY", dict(trackers.base.REGISTRY))  # the plugin joins a copy
    (tmp_path / "mineplug").mkdir()
    (tmp_path / "mineplug" / "__init__.py").write_text("")
    (tmp_path / "mineplug" / "tracker.py").write_text(MINE)
    dist = tmp_path / "mineplug-0.1.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: mineplug\nVersion: 0.1\n")
    (dist / "entry_points.txt").write_text("[mtt_sim.trackers]\nmine_plugin = mineplug.tracker:Mine\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    assert trackers.make("mineplug.tracker:Mine:min_confidence=0.1").params["min_confidence"] == 0.1
    assert "mine_plugin" in trackers.available()
    assert trackers.make("mine_plugin:min_confidence=0.7").params["min_confidence"] == 0.7
    assert trackers.base.search_space("mine_plugin") == {"min_confidence": trackers.base.REGISTRY["mine_plugin"]
                                                         .parameters["min_confidence"]}

"""The experiment runner: reproducible records, parallel equals serial, interval arithmetic, tables."""

import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from mtt_sim import trackers
from helpers import fail_on_two
from mtt_sim.lab import experiment
from mtt_sim.lab import pool


def strip_speed(records):
    """The records without their timings, as text (so that a NaN equals a NaN)."""
    return json.dumps([{k: v for k, v in r.items() if k not in ("tracker_fps", "env_fps")} for r in records])


def test_parallel_grid_equals_serial_and_is_in_grid_order():
    args = (["sort", "gnn:coast=true"], ["clutter_storm", "crossing"], 2)
    cfg = {"env.max_steps": 12}
    serial = experiment.run_grid(*args, config=cfg, workers=1)
    parallel = experiment.run_grid(*args, config=cfg, workers=2)
    assert strip_speed(serial) == strip_speed(parallel)
    assert [(r["scenario"], r["tracker"], r["seed"]) for r in serial][:4] == [
        ("clutter_storm", "sort", 0), ("clutter_storm", "sort", 1), ("clutter_storm", "gnn:coast=true", 0),
        ("clutter_storm", "gnn:coast=true", 1)]
    assert serial[2]["params"]["coast"] is True and all(r["tracker_fps"] > 0 for r in serial)


def test_ray_backend_gives_the_records_of_the_local_backend(capsys):
    pytest.importorskip("ray", reason="the ray backend needs the [ray] extra (CI installs it)")
    args = (["sort", "lmb:reid=false"], ["clutter_storm"], 2)
    cfg = {"env.max_steps": 10}
    local = experiment.run_grid(*args, config=cfg, workers=1)
    on_ray = experiment.run_grid(*args, config=cfg, workers=2, backend="ray", progress=True)
    assert strip_speed(on_ray) == strip_speed(local)
    assert "4/4" in capsys.readouterr().err
    with pytest.raises(ValueError, match="backend='spark': allowed values: 'local', 'ray'"):
        experiment.run_grid(*args, backend="spark")


def test_bad_tracker_spec_fails_before_any_work():
    with pytest.raises(ValueError, match="unknown tracker 'nope'"):
        experiment.run_grid(["sort", "nope"], ["crossing"], 1)


def test_mean_ci_known_values():
    mean, half = experiment.mean_ci([1.0, 2.0, 3.0])
    assert mean == 2.0 and half == pytest.approx(4.302653 / math.sqrt(3), rel=1e-6)
    assert experiment.mean_ci([5.0]) == (5.0, 0.0)


def test_summarize_and_markdown():
    records = [{"tracker": t, "scenario": s, "config": {}, "metrics": {"MOTA": m}, "tracker_fps": 100.0, "env_fps": 1.0}
               for t, s, m in [("a", "x", 0.5), ("a", "x", 0.7), ("b", "x", 0.1), ("b", "x", 0.1)]]
    rows = experiment.summarize(records, "MOTA")
    assert [(r["tracker"], round(r["mean"], 6), r["n"]) for r in rows] == [("a", 0.6, 2), ("b", 0.1, 2)]
    table = experiment.markdown(rows)
    assert "| a | 0.600 ± " in table and "| b | 0.100 ± 0.000 | 100 | 1 |" in table
    with pytest.raises(ValueError, match="unknown metric 'MOTX'"):
        experiment.summarize(records, "MOTX")


def test_summarize_by_target_averages_each_ground_truth_id_over_seeds():
    records = [{"tracker": "a", "scenario": "x", "config": {}, "metrics": {}, "tracker_fps": 1.0, "env_fps": 1.0,
                "per_target": {1: {"CentreError": e1, "Coverage": 1.0}, 2: {"CentreError": e2, "Coverage": c2}}}
               for e1, e2, c2 in [(1.0, 4.0, 0.5), (3.0, math.nan, 0.0)]]
    rows = experiment.summarize(records, "CentreError", by="target")
    assert [(r["column"], r["mean"]) for r in rows] == [("target 1", 2.0), ("target 2", 4.0)]  # never matched: no error
    assert [r["mean"] for r in experiment.summarize(records, "Coverage", by="target")] == [1.0, 0.25]
    with pytest.raises(ValueError, match="unknown per-target metric 'MOTA'; available: CentreError, Coverage"):
        experiment.summarize(records, "MOTA", by="target")


def test_pool_survives_a_failing_task_and_a_dying_worker():
    got = dict(pool.run(fail_on_two, [0, 1, 2, 3, 4, 5], workers=2))
    assert {k: v for k, v in got.items() if not isinstance(v, pool.TaskFailed)} == {0: 0, 1: 2, 4: 8, 5: 10}
    assert got[2].message == "ValueError: two is not allowed"
    assert got[3].message == "worker process died (exit code -9)"


class FailsOnItsSecondEpisode(trackers.Tracker):
    name = "fails_second"
    episodes = 0

    def reset(self, info=None):
        type(self).episodes += 1
        self.inner = trackers.make("sort")
        self.inner.reset(info)

    def update(self, obs):
        if type(self).episodes == 2:
            raise RuntimeError("bad luck\nsecond line")
        return self.inner.update(obs)


def test_a_failing_episode_is_recorded_and_the_grid_goes_on(monkeypatch, tmp_path):
    monkeypatch.setitem(trackers.base.REGISTRY, "fails_second", FailsOnItsSecondEpisode)
    written = []
    records = experiment.run_grid(["fails_second", "sort"], ["clutter_storm"], 3, config={"env.max_steps": 5},
                                  on_record=written.append)
    assert [r["error"] for r in records] == [None, "RuntimeError: bad luck", None, None, None, None]
    assert records[1]["metrics"] is None and written == records  # handed over as they finished
    table = experiment.markdown(experiment.summarize(records, "MOTA"))
    assert "| fails_second | " in table and "(1 of 3 failed)" in table
    assert "| sort | " in experiment.markdown(experiment.summarize(records[3:4], "IDSW"))  # one seed: "0", no interval
    assert experiment.markdown(experiment.summarize(records[3:4], "IDSW")).splitlines()[-1].split(" | ")[1] == "0"
    all_failed = experiment.markdown(experiment.summarize(records[1:2], "MOTA"))
    assert "| fails_second | failed | - | - |" in all_failed
    experiment.write_records(records, tmp_path / "r.json")
    assert json.loads((tmp_path / "r.json").read_text())[1]["error"] == "RuntimeError: bad luck"


def _children(pid: int) -> list[int]:
    """The worker processes of `pid` (Linux /proc)."""
    kids = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
            cmdline = (stat.parent / "cmdline").read_bytes()
        except OSError:
            continue
        if int(fields[1]) == pid and b"spawn_main" in cmdline:
            kids.append(int(stat.parent.name))
    return kids


def _bench(tmp_path, seeds, steps):
    return subprocess.Popen([sys.executable, "-m", "mtt_sim.cli", "bench", "--scenarios", "dense", "--trackers", "sort",
                             "--seeds", str(seeds), "--workers", "2", "--config", f"env.max_steps={steps}",
                             "--out", str(tmp_path / "r.json")], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)


def _wait_for(condition, timeout=120):
    end = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < end, "timed out"
        time.sleep(0.2)


def test_a_killed_worker_costs_only_its_episode(tmp_path):
    run = _bench(tmp_path, seeds=3, steps=400)
    _wait_for(lambda: len(_children(run.pid)) == 2)
    time.sleep(3)  # both workers are inside an episode
    os.kill(_children(run.pid)[0], signal.SIGKILL)
    out, err = run.communicate(timeout=300)
    assert run.returncode == 1, err
    assert "1 of 3 episodes failed" in out and "worker process died (exit code -9)" in out
    records = json.loads((tmp_path / "r.json").read_text())
    assert [r["seed"] for r in records] == [0, 1, 2] and sum(bool(r["error"]) for r in records) == 1


def test_sigterm_stops_the_workers_and_keeps_the_finished_records(tmp_path):
    run = _bench(tmp_path, seeds=6, steps=150)
    records = tmp_path / "r.json"
    _wait_for(lambda: records.exists() and json.loads(records.read_text()))
    workers = _children(run.pid)
    run.send_signal(signal.SIGTERM)
    out, err = run.communicate(timeout=60)
    assert run.returncode == 130 and "interrupted;" in err and "episodes finished" in err
    kept = json.loads(records.read_text())
    assert 1 <= len(kept) < 6 and all(r["error"] is None for r in kept)
    assert "| sort |" in out  # the table of what finished
    _wait_for(lambda: not any(Path(f"/proc/{w}").exists() for w in workers), timeout=10)

"""The experiment runner: reproducible records, parallel equals serial, interval arithmetic, tables."""

import math

import pytest

from mtt_sim import experiment


def strip_speed(records):
    return [{k: v for k, v in r.items() if k not in ("tracker_fps", "env_fps")} for r in records]


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

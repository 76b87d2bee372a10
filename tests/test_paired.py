"""docs/experiments/paired.py: paired differences of a metric, and a MOTA lead split into its FN, FP and IDSW
parts, on hand-made records."""

import csv
import json
import importlib.util

import pytest

from helpers import EXPERIMENTS

spec = importlib.util.spec_from_file_location("paired", EXPERIMENTS / "paired.py")
paired = importlib.util.module_from_spec(spec)
spec.loader.exec_module(paired)


def records(path, rows):
    """rows: (tracker, seed, FN, FP, IDSW) over 100 ground-truth boxes; MOTA from them."""
    with open(path, "w", newline="") as f:
        out = csv.writer(f)
        out.writerow(["tracker", "scenario", "seed", "config", "error", "MOTA", "FN", "FP", "IDSW", "num_gt_dets"])
        for tracker, seed, fn, fp, idsw in rows:
            out.writerow([tracker, "s", seed, "{}", "", 1 - (fn + fp + idsw) / 100, fn, fp, idsw, 100])


def test_the_parts_of_a_lead_are_the_count_differences_over_the_truth_and_add_up(tmp_path):
    path = tmp_path / "r.csv"
    records(path, [("a", 0, 10, 20, 1), ("a", 1, 12, 18, 2), ("a", 2, 5, 5, 5),   # seed 2: b did not run it
                   ("b", 0, 30, 10, 1), ("b", 1, 28, 12, 4)])
    d = paired.difference(*(paired.episodes(str(path))[t, "s"] for t in ("a", "b")), "MOTA")
    assert d["seeds"] == 2
    assert d["FN"][0] == pytest.approx(18.0) and d["FP"][0] == pytest.approx(-8.0) and d["IDSW"][0] == pytest.approx(1)
    assert d["MOTA"][0] == pytest.approx(d["FN"][0] + d["FP"][0] + d["IDSW"][0])
    assert d["MOTA"][1] == pytest.approx(12.706, rel=1e-4)   # leads 10 and 12: t(0.975, 1) x sqrt(2) / sqrt(2)


def test_a_pair_without_records_names_the_trackers(tmp_path, capsys):
    path = tmp_path / "r.csv"
    records(path, [("a", 0, 1, 1, 0), ("b", 0, 2, 2, 0)])
    with pytest.raises(SystemExit, match="no records of 'a' and 'c' in s; trackers: a, b"):
        paired.main(str(path), "MOTA", ["a vs c"])
    with pytest.raises(SystemExit, match="expected 'A vs B'"):
        paired.main(str(path), "MOTA", ["a - b"])


def test_json_records_pair_only_the_seeds_where_both_have_a_value(tmp_path):
    """Reacquired is None in an episode without occlusions; such a seed drops out of the pairing."""
    def record(tracker, seed, value, error=None):
        return {"tracker": tracker, "scenario": "docs/x.toml", "seed": seed, "config": {}, "error": error,
                "metrics": None if error else {"Reacquired": value}}
    path = tmp_path / "r.json"
    path.write_text(json.dumps([record("a", 0, 1.0), record("a", 1, None), record("a", 2, 0.5), record("a", 3, 1.0),
                                record("b", 0, 0.0), record("b", 1, 0.0), record("b", 2, 0.25),
                                record("b", 3, 0.0, error="boom")]))
    cells = paired.episodes(str(path))
    assert set(cells) == {("a", "x"), ("b", "x")} and sorted(cells["b", "x"]) == [0, 1, 2]
    d = paired.difference(cells["a", "x"], cells["b", "x"], "Reacquired")
    assert d["seeds"] == 2 and d["Reacquired"][0] == pytest.approx((1.0 + 0.25) / 2)

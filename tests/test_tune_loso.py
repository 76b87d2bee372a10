"""docs/experiments/tune_loso.py: leave-one-sequence-out picks and their held-out scores, from hand-made rows."""

import importlib.util

import pytest

from helpers import EXPERIMENTS

pytest.importorskip("optuna")
spec = importlib.util.spec_from_file_location("tune_loso", EXPERIMENTS / "tune_loso.py")
tune_loso = importlib.util.module_from_spec(spec)
spec.loader.exec_module(tune_loso)


def row(candidate, hota):
    return {"tracker": "sort", "candidate": candidate, "spec": f"sort:max_age={candidate + 1}",
            "scores": {s: {"MOTA": 0.0, "IDF1": 0.0, "HOTA": h} for s, h in zip("ABCD", hota)}}


def test_each_sequence_is_scored_by_the_pick_of_the_others():
    # candidate 1 beats the defaults on A, B and C and loses on D; every fold picks it (its mean over any three is
    # above 0.5), so it scores 0.7 on A, B and C held out and 0.2 on D: a mean 0.575, at least the defaults on 3 of 4
    table = tune_loso.table([row(0, (0.5, 0.5, 0.5, 0.5)), row(1, (0.7, 0.7, 0.7, 0.2))], "HOTA")
    line = next(line for line in table.splitlines() if line.startswith("| sort |"))
    assert line == "| sort | 1 | 0.0 | 0.0 | 0.0 | 0.0 | 50.0 | 57.5 | 3 of 4 |"

"""docs/experiments/one_parameter.py: a tuned spec's parameters tried one at a time on a hand-made sequence."""

import importlib.util
import json

import pytest

from helpers import EXPERIMENTS, write_sequence

spec = importlib.util.spec_from_file_location("one_parameter", EXPERIMENTS / "one_parameter.py")
one_parameter = importlib.util.module_from_spec(spec)
spec.loader.exec_module(one_parameter)


def standing_person(tmp_path):
    """One person detected in frames 1-4 and 7-10 (missed in 5-6): SORT's max_age decides whether one track or two."""
    box = (20.0, 20.0, 10.0, 20.0)
    frames = [*range(1, 5), *range(7, 11)]
    return write_sequence(tmp_path / "seq", det=[(f, *box, 1.0) for f in frames],
                          gt=[(f, 1, *box, 1, 1, 1.0) for f in range(1, 11)])


def test_each_parameter_alone_is_the_defaults_with_that_one_changed(tmp_path):
    folder = str(standing_person(tmp_path))
    got = dict(one_parameter.one_at_a_time(folder, "sort", "sort:max_age=5,min_hits=3", "IDSW"))
    assert got == {"max_age=5": 0, "min_hits=3": 1}  # kept through the miss: one track; SORT's max_age 1: two
    # a parameter the tracker was tuned with fixed (as lmb:reid=false) stays in every run and is not tried alone
    assert dict(one_parameter.one_at_a_time(folder, "sort:min_hits=3", "sort:min_hits=3,max_age=5", "IDSW")) == {
        "max_age=5": 0}


def test_a_route_without_rows_is_one_clear_line(tmp_path, monkeypatch):
    rows = tmp_path / "rows.jsonl"
    rows.write_text(json.dumps({"sequence": "seq", "tracker": "sort", "route": "twin", "defaults": 0.5,
                                "real": 0.5, "spec": "sort:max_age=2"}) + "\n")
    monkeypatch.setattr("sys.argv", ["one_parameter.py", str(tmp_path), str(rows), "--tracker", "sort"])
    with pytest.raises(SystemExit, match="no row of tracker 'sort' on route 'generic'"):
        one_parameter.main()

"""The command line resolves once: a sequence folder's files are read once a command, a tracker spec is parsed once a
process and no tracker is built only to check its spec (issue 40, part 6)."""

import builtins
import collections
import io
from pathlib import Path

import pytest

from mtt_sim import cli
from mtt_sim.lab import experiment
from mtt_sim.trackers import base

from helpers import write_sequence

DET = [(f, 10.0 + f, 10.0, 20.0, 40.0, 0.9) for f in range(1, 6)]
GT = [(f, 1, 10.0 + f, 10.0, 20.0, 40.0, 1, 1, 1.0) for f in range(1, 6)]
FILES = ("det/det.txt", "gt/gt.txt", "seqinfo.ini")


@pytest.fixture
def counts(tmp_path, monkeypatch):
    """Two sequence folders, and what is counted while a test runs: the files read under tmp_path, the specs parsed
    and the trackers built, by name."""
    found = {"reads": collections.Counter(), "parsed": collections.Counter(), "built": collections.Counter(),
             "root": tmp_path}
    for name in ("a", "b"):
        write_sequence(tmp_path / name, det=DET, gt=GT, length=5)
    real_open, real_parse, real_init = builtins.open, base.parse_spec, base.Tracker.__init__

    def opened(file, *args, **kwargs):
        if isinstance(file, (str, Path)) and str(file).startswith(str(tmp_path)):
            found["reads"][Path(file).relative_to(tmp_path).as_posix()] += 1
        return real_open(file, *args, **kwargs)

    def parsed(spec):
        found["parsed"][spec] += 1
        return real_parse(spec)

    def built(self, **params):
        found["built"][self.name] += 1
        real_init(self, **params)

    monkeypatch.setattr(builtins, "open", opened)
    monkeypatch.setattr(io, "open", opened)
    monkeypatch.setattr(base, "parse_spec", parsed)
    monkeypatch.setattr(base.Tracker, "__init__", built)
    return found


def once(*folders) -> dict:
    return {f"{folder}/{name}": 1 for folder in folders for name in FILES}


def test_run_reads_the_sequence_once_and_parses_and_builds_its_tracker_once(counts, capsys):
    assert cli.main(["run", str(counts["root"] / "a"), "--tracker", "sort"]) == 0
    assert counts["reads"] == once("a")
    assert counts["parsed"] == {"sort": 1} and counts["built"] == {"sort": 1}


def test_compare_reads_the_sequence_once_for_all_its_envs(counts, capsys):
    assert cli.main(["run", str(counts["root"] / "a"), "--compare", "sort,iou"]) == 0
    assert counts["reads"] == once("a")
    assert counts["parsed"] == {"sort": 1, "iou": 1} and counts["built"] == {"sort": 1, "iou": 1}


def test_bench_reads_each_sequence_once_and_builds_a_tracker_an_episode(counts, capsys):
    folders = f"{counts['root'] / 'a'},{counts['root'] / 'b'}"
    assert cli.main(["bench", "--scenarios", folders, "--trackers", "sort,iou", "--seeds", "2"]) == 0
    assert counts["reads"] == once("a", "b")
    assert counts["parsed"] == {"sort": 1, "iou": 1}
    assert counts["built"] == {"sort": 4, "iou": 4}  # 2 sequences x 2 seeds each: none built only to check


def test_a_worker_parses_what_its_tasks_name_once(counts):
    """Tasks cross processes as strings; the process that runs them parses each once, however many there are."""
    folder = str(counts["root"] / "a")
    here = experiment._Episodes()
    records = [here((folder, "sort:max_age=3", seed, {}, None)) for seed in range(3)]
    assert [r["error"] for r in records] == [None] * 3
    assert {r["tracker"] for r in records} == {"sort:max_age=3"} and type(records[0]["tracker"]) is str
    assert counts["reads"] == once("a")
    assert counts["parsed"] == {"sort:max_age=3": 1} and counts["built"] == {"sort": 3}


def test_parsed_sources_and_specs_cross_processes_as_plain_strings(counts):
    """What a worker is sent is the string: it reads and parses for itself, and nothing read here is pickled."""
    import pickle

    from mtt_sim.sources import SourceSpec
    from mtt_sim.trackers import TrackerSpec

    source, spec = SourceSpec(str(counts["root"] / "a")), TrackerSpec("SORT:max_age=3", canonical=True)
    source.open()
    for parsed, text in ((source, str(counts["root"] / "a")), (spec, "sort:max_age=3")):
        sent = pickle.loads(pickle.dumps(parsed))
        assert sent == text and type(sent) is str


def test_dry_run_reads_the_sequence_once(counts, capsys):
    assert cli.main(["run", str(counts["root"] / "a"), "--dry-run"]) == 0
    assert counts["reads"] == once("a") and counts["built"] == {"sort": 1}


def test_tune_reads_its_sequence_and_parses_its_spec_once_a_study(counts, capsys):
    pytest.importorskip("optuna")
    assert cli.main(["tune", "sort", "--on", str(counts["root"] / "a"), "--trials", "2", "--seeds", "1"]) == 0
    assert counts["reads"] == once("a")
    assert counts["parsed"]["sort"] == 1  # the study's spec, parsed once for its definition, name and space

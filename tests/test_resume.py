"""--resume: a long command interrupted after any piece of its work, then rerun with --resume (perhaps interrupted
again), ends with the outputs of an uninterrupted run, byte for byte but for the timing columns; and the journal that
makes it so keeps exactly what finished."""

import csv
import io
import json
import pickle

import numpy as np
import pytest

from mtt_sim import cli
from mtt_sim.lab.journal import Journal, JournalMismatch

SHORT = ["--config", "env.max_steps=25"]
COMMANDS = {
    "bench": ["bench", "--scenarios", "mot17_like,crossing", "--trackers", "sort,iou", "--seeds", "2", "--out",
              "records.json", *SHORT],
    "sweep": ["sweep", "mot17_like", "--param", "sensor.pd=0.6,0.9", "--trackers", "sort", "--seeds", "2", "--out",
              "records.csv", *SHORT],
    "stress": ["stress", "sort", "--scenario", "mot17_like", "--vary", "sensor.pd=0.5:0.95,sensor.clutter_rate=0:8",
               "--budget", "4", "--seeds", "2", "--top", "2", "--out", "worst", *SHORT],
    "learn-policy": ["learn-policy", "--on", "mot17_like", "--seeds", "2", "--frames", "25", "--generations", "2",
                     "--population", "4", "--out", "policy.npz", "--plot", "curve.png"],
}
PIECES = {"bench": 8, "sweep": 4, "stress": 8, "learn-policy": 2 + 2 * (1 + 2 * 4)}  # what each journals in all


def outputs(folder) -> dict:
    """Every file a run left in `folder`, as bytes; the records without their timing columns."""
    files = {}
    for path in sorted(p for p in folder.rglob("*") if p.is_file()):
        data = path.read_bytes()
        if path.name == "records.json":
            data = [{k: v for k, v in r.items() if not k.endswith("_fps")} for r in json.loads(data)]
        elif path.name == "records.csv":
            data = [row[:6] + row[8:] for row in csv.reader(io.StringIO(data.decode()))]
        files[str(path.relative_to(folder))] = data
    return files


def tables(printed: str) -> str:
    """What a run printed, without the timing columns of its tables."""
    return "\n".join(line.rsplit("|", 3)[0] if line.startswith("| ") else line for line in printed.splitlines())


DONE = []  # the pieces of work the last run did


def run(argv, folder, monkeypatch, capsys, stop_after=None) -> tuple[int, str, str]:
    """The command in `folder`, interrupted (as by Ctrl-C) right after its journal's `stop_after`-th new piece."""
    put = Journal.put
    DONE.clear()

    def counting(self, key, value):
        put(self, key, value)
        DONE.append(key)
        if len(DONE) == stop_after:
            raise KeyboardInterrupt
    with monkeypatch.context() as patch:
        patch.chdir(folder)
        patch.setattr(Journal, "put", counting)
        code = cli.main(argv)
    return code, *capsys.readouterr()


@pytest.mark.parametrize("command", COMMANDS)
def test_an_interrupted_run_resumed_ends_as_an_uninterrupted_one(command, tmp_path, monkeypatch, capsys):
    argv = COMMANDS[command]
    (tmp_path / "whole").mkdir()
    code, printed, _ = run(argv, tmp_path / "whole", monkeypatch, capsys)
    assert code == 0 and not list((tmp_path / "whole").glob("*.journal")) and len(DONE) == PIECES[command]
    whole = outputs(tmp_path / "whole")
    for stops in ([1], [PIECES[command] // 2, 1], [PIECES[command] - 1]):  # early; twice; at the very end
        folder = tmp_path / "-".join(map(str, stops))
        folder.mkdir()
        for k, stop in enumerate(stops):
            code, *_ = run(argv + (["--resume"] if k else []), folder, monkeypatch, capsys, stop)
            assert code == cli.INTERRUPTED and list(folder.glob("*.journal"))
        assert run(argv, folder, monkeypatch, capsys)[0] == 2  # not over an interrupted run's journal unasked
        code, again, _ = run(argv + ["--resume"], folder, monkeypatch, capsys)
        assert code == 0 and tables(again) == tables(printed)
        assert len(DONE) == PIECES[command] - sum(stops)  # only what was missing
        assert outputs(folder) == whole, f"{command} interrupted after {stops} pieces"


def test_resume_with_other_arguments_is_refused_naming_what_differs(tmp_path, monkeypatch, capsys):
    argv = COMMANDS["bench"]
    run(argv, tmp_path, monkeypatch, capsys, stop_after=1)
    other = [("3" if a == "2" else a) for a in argv]  # three seeds, not two
    code, _, err = run(other + ["--resume"], tmp_path, monkeypatch, capsys)
    assert code == 2 and "argument --resume: journal records.json.journal is of another run (seeds: [0, 1] then, [0, 1, 2] now)" in err
    assert run(other + ["--force"], tmp_path, monkeypatch, capsys)[0] == 0  # --force starts over


def test_resume_needs_an_unfinished_output(tmp_path, monkeypatch, capsys):
    argv = COMMANDS["sweep"]
    code, _, err = run(argv[:-4] + SHORT + ["--resume"], tmp_path, monkeypatch, capsys)  # no --out
    assert code == 2 and "argument --resume: needs --out" in err
    assert run(argv, tmp_path, monkeypatch, capsys)[0] == 0
    code, _, err = run(argv + ["--resume"], tmp_path, monkeypatch, capsys)
    assert code == 2 and "is a finished run's (no records.csv.journal beside it): nothing to resume" in err


def test_the_journal_keeps_what_finished_exactly_and_drops_a_piece_cut_off(tmp_path):
    path, definition = tmp_path / "run.journal", {"seeds": [0, 1], "config": {"sensor.pd": 0.9}}
    journal = Journal(path, definition, resume=False)
    journal.put(("score", "abc"), 0.1 + 0.2)
    journal.put("record", {"per_target": {1: 0.5}, "weights": np.arange(3.0)})
    journal.close()
    with path.open("ab") as f:  # a piece cut off mid-write by the interruption
        f.write(pickle.dumps(("late", 1.0))[:-3])
    again = Journal(path, definition, resume=True)
    assert again.resumed == 2 and again.get(("score", "abc")) == 0.30000000000000004 and "late" not in again
    assert list(again.get("record")["per_target"]) == [1] and (again.get("record")["weights"] == [0, 1, 2]).all()
    again.put("next", 2)
    again.close()
    assert Journal(path, definition, resume=True).get("next") == 2  # written after the whole pieces, not the cut one
    with pytest.raises(JournalMismatch, match=r"of another run \(config: \{'sensor.pd': 0.9\} then, \{\} now\)"):
        Journal(path, {"seeds": [0, 1], "config": {}}, resume=True)
    fresh = Journal(path, definition, resume=False)
    assert fresh.resumed == 0 and "next" not in fresh
    fresh.finish()
    assert not path.exists()

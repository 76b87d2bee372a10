"""The mtt-sim command."""

import csv
import json
import subprocess
import sys

import cv2
import pytest

from mtt_sim import cli, perf


def mtt_sim(*args):
    return subprocess.run([sys.executable, "-m", "mtt_sim.cli", *args], capture_output=True, text=True, timeout=300)


def test_list_names_every_scenario_with_its_env_id():
    out = mtt_sim("list")
    assert out.returncode == 0
    assert "crossing" in out.stdout and "mtt_sim/Crossing-v0" in out.stdout and len(out.stdout.splitlines()) >= 8


def test_run_prints_a_summary_and_writes_a_video(tmp_path, capsys):
    video = tmp_path / "out.mp4"
    assert cli.main(["run", "crossing", "--tracker", "gnn", "--seed", "0", "--steps", "30", "--video", str(video),
                     "--config", "sensor.clutter_rate=2"]) == 0
    text = capsys.readouterr().out
    assert "MOTA" in text and "HOTA" in text and "tracker_fps" in text
    cap = cv2.VideoCapture(str(video))
    assert int(cap.get(cv2.CAP_PROP_FRAME_COUNT)) == 30 and int(cap.get(cv2.CAP_PROP_FRAME_WIDTH)) == 384


def test_run_json_is_deterministic(capsys):
    cli.main(["run", "clutter_storm", "--tracker", "sort", "--steps", "20", "--json"])
    first = json.loads(capsys.readouterr().out)
    cli.main(["run", "clutter_storm", "--tracker", "sort", "--steps", "20", "--json"])
    again = json.loads(capsys.readouterr().out)
    drop = ("tracker_fps", "env_fps")
    assert {k: v for k, v in first.items() if k not in drop} == {k: v for k, v in again.items() if k not in drop}
    assert first["num_frames"] == 20


def test_bench_table_and_records(tmp_path, capsys):
    out = tmp_path / "r.csv"
    assert cli.main(["bench", "--trackers", "sort,iou", "--scenarios", "clutter_storm,books", "--seeds", "2",
                     "--config", "env.max_steps=15", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "| tracker | clutter_storm | books | tracker frames/s | env frames/s |" in text and "| sort | " in text
    rows = list(csv.DictReader(out.open()))
    assert len(rows) == 8 and {r["tracker"] for r in rows} == {"sort", "iou"} and "MOTA" in rows[0]


def test_sweep_without_matplotlib_says_how_to_install(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    code = cli.main(["sweep", "clutter_storm", "--param", "sensor.clutter_rate=0,10", "--trackers", "sort",
                     "--seeds", "1", "--config", "env.max_steps=10", "--plot", str(tmp_path / "p.png")])
    captured = capsys.readouterr()
    assert "clutter_rate=0" in captured.out and "clutter_rate=10" in captured.out
    assert code == 2 and "pip install 'mtt-sim[plot]'" in captured.err


def test_errors_are_one_line_with_exit_code_two():
    out = mtt_sim("run", "nowhere")
    assert out.returncode == 2 and out.stderr.startswith("mtt-sim: error: unknown scenario 'nowhere'")
    out = mtt_sim("run", "crossing", "--config", "sensor.pd=2")
    assert out.returncode == 2 and "sensor.pd = 2" in out.stderr and "Traceback" not in out.stderr


@pytest.mark.parametrize("text, value", [("sensor.pd=0.5", 0.5), ("render.camera=shake", "shake"),
                                         ("world.walls=true", True), ("groups.0.size=[10, 20]", [10, 20])])
def test_config_values_are_read_as_toml(text, value):
    assert cli.parse_overrides([text]) == {text.split("=")[0]: value}


def test_config_reference_and_perf_report_shape(capsys):
    assert cli.main(["config"]) == 0
    assert "| `sensor.clutter_rate` |" in capsys.readouterr().out
    rows = perf.measure(repeats=1, steps=4)
    assert [r["targets"] for r in rows] == [20, 200]
    assert all(r["frames_steps_per_s"] > 0 and r["step_over_reference"] > 0 for r in rows)
    assert "step / reference" in perf.report(rows)
    rows = perf.measure_metrics(repeats=1)
    assert [r["objects"] for r in rows] == [20, 200] and all(r["update_us"] > 0 and r["summary_s"] > 0 for r in rows)
    assert "update / reference" in perf.report_metrics(rows)
    rows = perf.measure_pf(repeats=1, frames=2)
    assert [r["tracker"].split()[0] for r in rows] == ["pf", "ipf"] and all(r["fps"] > 0 for r in rows)
    assert "| ipf (seed 002), 4 x 100 particles, 640x480 |" in perf.report_pf(rows)


def test_sweep_writes_a_plot(tmp_path, capsys):
    plot = tmp_path / "curve.png"
    assert cli.main(["sweep", "clutter_storm", "--param", "sensor.clutter_rate=0,20", "--trackers", "sort,iou",
                     "--seeds", "2", "--config", "env.max_steps=10", "--plot", str(plot)]) == 0
    assert plot.stat().st_size > 1000 and cv2.imread(str(plot)).shape[2] == 3

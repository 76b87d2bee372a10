"""The mtt-sim command."""

import argparse
import csv
import importlib.metadata
import json
import math
import re
import subprocess
import sys

import cv2
import pytest

from helpers import exit_code
from mtt_sim import trackers
from mtt_sim import cli
from mtt_sim.cli import arguments
from mtt_sim.lab import docsite, experiment
from mtt_sim.lab import perf, perf_motion
from mtt_sim.sim import scenario


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
    fourcc = int(cap.get(cv2.CAP_PROP_FOURCC)).to_bytes(4, "little").decode()
    assert fourcc in ("avc1", "h264", "H264")  # H.264: browsers, Jupyter and GitHub play it


def test_compare_writes_one_panel_per_tracker_side_by_side_as_a_gif(tmp_path, capsys):
    import imageio_ffmpeg

    gif = tmp_path / "side.gif"
    assert cli.main(["run", "crossing", "--compare", "sort,jpda", "--steps", "6", "--scale", "2",
                     "--video", str(gif)]) == 0
    out = capsys.readouterr().out
    assert out.count("MOTA") == 2 and "jpda" in out
    frames = imageio_ffmpeg.read_frames(str(gif))
    meta = next(frames)
    assert gif.read_bytes()[:4] == b"GIF8" and tuple(meta["size"]) == (2 * 2 * 384 + 4, 2 * 288)
    assert sum(1 for _ in frames) == 3  # a GIF keeps every other frame


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


def test_sweep_without_matplotlib_says_how_to_install_before_any_work(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    code = cli.main(["sweep", "clutter_storm", "--param", "sensor.clutter_rate=0,10", "--trackers", "sort",
                     "--seeds", "1", "--config", "env.max_steps=10", "--plot", str(tmp_path / "p.png")])
    captured = capsys.readouterr()
    assert code == 2 and "argument --plot: needs matplotlib: pip install 'mtt-sim[plot]'" in captured.err
    assert "clutter_rate=0" not in captured.out  # nothing ran


def test_every_help_works():
    for argv in (["--help"], ["-h"]):
        out = mtt_sim(*argv)
        assert out.returncode == 0 and "95% interval" in out.stdout
    commands = next(a for a in cli.build_parser()._actions if isinstance(a, argparse._SubParsersAction)).choices
    assert {"run", "bench", "sweep", "perf", "config", "learn-reid", "export", "eval", "list", "trackers"} <= set(commands)
    for name in commands:
        with pytest.raises(SystemExit) as done:
            cli.main([name, "--help"])
        assert done.value.code == 0, name


def test_version_is_the_installed_one():
    out = mtt_sim("--version")
    assert out.returncode == 0 and out.stdout.strip() == f"mtt-sim {importlib.metadata.version('mtt-sim')}"


BAD_ARGUMENTS = [
    (["run", "crossing", "--steps", "-5"], r"argument --steps: must be an integer >= 1, got '-5'"),
    (["run", "crossing", "--seed", "-1"], r"argument --seed: must be an integer >= 0, got '-1'"),
    (["run", "socer"], r"unknown scenario 'socer' \(did you mean 'soccer'\?\)"),
    (["run", "crossing", "--tracker", "sortt"], r"unknown tracker 'sortt' \(did you mean 'sort'\?\)"),
    (["run", "crossing", "--tracker", "sort:max_age=-5"], r"parameter max_age='-5': allowed: an integer in \[0, inf\)"),
    (["run", "crossing", "--config", "sensor.pd=2"], r"argument --config: .*sensor\.pd = 2: out of range"),
    (["run", "crossing", "--video", "out.avi"], r"argument --video: 'out.avi': the file name must end in \.mp4 or \.gif"),
    (["run", "crossing", "--compare", "sort,iou", "--results", "r.txt"], r"argument --results: a results file takes one tracker"),
    (["run", "crossing", "--scale", "9"], r"argument --scale: must be an integer in 1..8"),
    (["run", "crossing", "--compare", "sort,nope"], r"argument --compare: .*nope"),
    (["run", "crossing", "--video", "/nowhere/out.mp4"], r"argument --video: .* folder '/nowhere' does not exist"),
    (["bench", "--scenarios", "crossing,nope", "--trackers", "sort"], r"argument --scenarios: unknown scenario 'nope'"),
    (["bench", "--scenarios", "crossing", "--trackers", "sort", "--metric", "MOTA,hotaa"],
     r"argument --metric: unknown metric 'hotaa' \(did you mean 'HOTA'\?\)"),
    (["bench", "--scenarios", "crossing", "--trackers", "sort", "--seeds", "0"], r"argument --seeds: '0': expected a count"),
    (["bench", "--scenarios", "crossing", "--trackers", "sort", "--seeds", "9-3"], r"argument --seeds: '9-3'"),
    (["bench", "--scenarios", "crossing", "--trackers", "sort", "--seeds", "1,1"], r"a seed is given twice"),
    (["bench", "--scenarios", "crossing", "--trackers", "sort", "--workers", "0"], r"argument --workers: must be"),
    (["bench", "--scenarios", "crossing", "--trackers", "sort", "--out", "r.txt"], r"must end in \.csv or \.json"),
    (["bench", "--scenarios", "crossing", "--trackers", "sort", "--by", "target"],
     r"argument --metric: with --by target: CentreError, Coverage, HiddenCentreError, Reacquired"),
    (["sweep", "crossing", "--param", "sensor.pd=0.5,2", "--trackers", "sort"], r"argument --param: .*sensor\.pd = 2"),
    (["sweep", "crossing", "--param", "sensor.pd", "--trackers", "sort"], r"argument --param: 'sensor.pd': expected key="),
    (["learn-reid", "--every", "0"], r"argument --every: must be an integer >= 1, got '0'"),
    (["learn-reid", "--out", "metric.txt"], r"argument --out: 'metric.txt': the file name must end in \.npz"),
    (["perf", "--repeats", "0"], r"argument --repeats: must be an integer >= 1"),
    (["export", "crossing", "--out", "seq", "--steps", "0"], r"argument --steps: must be an integer >= 1"),
    (["eval", "--gt", "nowhere", "--results", "r.txt"], r"argument --gt: 'nowhere/gt/gt.txt' not found"),
    (["eval", "--gt", "nowhere", "--results", "r.txt", "--threshold", "1.5"], r"--threshold: must be a number in \(0, 1\]"),
    (["config", "crossing", "--config", "sensor"], r"argument --config: 'sensor': expected key=value"),
]


@pytest.mark.parametrize("argv, pattern", BAD_ARGUMENTS)
def test_a_bad_argument_gets_one_line_and_exit_two_before_any_work(argv, pattern, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code = exit_code(argv)
    err = capsys.readouterr().err
    assert code == 2 and re.search(pattern, err), err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert not list(tmp_path.iterdir())  # nothing was written


def test_names_are_case_insensitive_and_env_ids_are_scenarios(capsys):
    assert cli.main(["run", "mtt_sim/ClutterStorm-v0", "--tracker", "SORT", "--steps", "3", "--json"]) == 0
    first = json.loads(capsys.readouterr().out)
    assert cli.main(["run", "Clutter_Storm", "--tracker", "sort", "--steps", "3", "--json"]) == 0
    again = json.loads(capsys.readouterr().out)
    assert first["scenario"] == again["scenario"] == "clutter_storm" and first["tracker"] == "sort"
    assert first["MOTA"] == again["MOTA"]
    assert cli.main(["bench", "--scenarios", "CROSSING", "--trackers", "Sort", "--seeds", "1", "--metric", "mota,Idf1",
                     "--config", "env.max_steps=3"]) == 0
    out = capsys.readouterr().out
    assert "MOTA (one seed)" in out and "IDF1 (one seed)" in out and "| sort | " in out and "| crossing |" in out


def test_tracker_specs_with_several_parameters_and_seed_forms(tmp_path, capsys):
    out = tmp_path / "r.csv"
    assert cli.main(["bench", "--scenarios", "clutter_storm", "--trackers", "sort:min_hits=1,max_age=5,iou,gnn:coast=true",
                     "--seeds", "3,7", "--config", "env.max_steps=4", "--out", str(out)]) == 0
    rows = list(csv.DictReader(out.open()))
    assert [r["tracker"] for r in rows] == ["sort:min_hits=1,max_age=5"] * 2 + ["iou"] * 2 + ["gnn:coast=true"] * 2
    assert json.loads(rows[0]["params"])["max_age"] == 5 and [r["seed"] for r in rows[:2]] == ["3", "7"]
    assert arguments.parse_seeds("100-102,7") == [100, 101, 102, 7] and arguments.parse_seeds("3") == [0, 1, 2]
    assert trackers.split_specs("sort:min_hits=1,max_age=5;iou") == ["sort:min_hits=1,max_age=5", "iou"]


def test_trackers_lists_every_tracker_with_its_parameters(capsys):
    assert cli.main(["trackers"]) == 0
    out = capsys.readouterr().out
    for name in trackers.available():
        assert f"\n{name}: " in "\n" + out
    assert "max_age=1" in out and "an integer in [0, inf)" in out and "'keep', 'zero'" in out
    assert "meas_sigma=4.0                     a number in (0, inf); detection centre noise, px" in out  # its unit


def test_an_existing_output_is_refused_unless_forced(tmp_path, capsys):
    out = tmp_path / "r.json"
    out.write_text("precious")
    args = ["bench", "--scenarios", "crossing", "--trackers", "sort", "--seeds", "1", "--config", "env.max_steps=3",
            "--out", str(out)]
    assert cli.main(args) == 2 and "exists; add --force to replace it" in capsys.readouterr().err
    assert out.read_text() == "precious"
    assert cli.main(args + ["--force"]) == 0 and "(replaced)" in capsys.readouterr().out
    assert len(json.loads(out.read_text())) == 1


def test_export_into_an_older_longer_export_leaves_no_stale_frames(tmp_path, capsys):
    seq = tmp_path / "seq"
    assert cli.main(["export", "crossing", "--out", str(seq), "--steps", "6"]) == 0
    assert cli.main(["export", "crossing", "--out", str(seq), "--steps", "3"]) == 2
    assert "not empty; add --force" in capsys.readouterr().err
    assert cli.main(["export", "crossing", "--out", str(seq), "--steps", "3", "--force"]) == 0
    assert sorted(p.name for p in (seq / "img1").iterdir()) == ["000001.jpg", "000002.jpg", "000003.jpg"]
    assert "exporting" in capsys.readouterr().err  # the progress bar


def test_a_long_run_shows_progress(monkeypatch, capsys):
    bars, tqdm = [], experiment.tqdm

    def spy(*args, **kwargs):  # the bar's settings kept, the bar itself hidden (an iterable or a context manager)
        bars.append(kwargs)
        return tqdm(*args, **{**kwargs, "disable": True})
    monkeypatch.setattr(experiment, "tqdm", spy)
    assert cli.main(["run", "crossing", "--steps", "3"]) == 0
    assert bars and bars[0]["delay"] == 1.0  # shown once a run has taken a second


@pytest.mark.parametrize("text, value", [("sensor.pd=0.5", 0.5), ("render.camera=shake", "shake"),
                                         ("world.walls=true", True), ("groups.0.size=[10, 20]", [10, 20])])
def test_config_values_are_read_as_toml(text, value):
    assert arguments.parse_overrides([text]) == {text.split("=")[0]: value}


def _table(text: str) -> tuple[list[str], list[list[str]]]:
    """A markdown table's header cells and body rows' cells."""
    lines = [line for line in text.splitlines() if line.startswith("|")]
    header, *rows = ([c.strip() for c in line.strip("|").split("|")] for line in lines)
    assert set(rows[0]) <= {"---", "---:"}
    return header, rows[1:]


def _printed(cell: str) -> tuple[float, float]:
    """A printed number ("1234", "0.52x", "12 us", "1.5 s") and half a unit of its last digit."""
    text = cell.split(" ")[0].removesuffix("x")
    return float(text), 0.5 * 10.0 ** -len(text.partition(".")[2])


def _is_ratio(ratio: str, top: str, bottom: str) -> bool:
    """The printed ratio is top / bottom of the printed columns, within the rounding of all three."""
    (r, dr), (t, dt), (b, db) = _printed(ratio), _printed(top), _printed(bottom)
    least = (t - dt) / (b + db)
    most = (t + dt) / (b - db) if b > db else math.inf
    return least <= r + dr and r - dr <= most


def test_config_reference_and_perf_report_shape(capsys):
    assert cli.main(["config"]) == 0
    assert "| `sensor.clutter_rate` |" in capsys.readouterr().out
    rows = perf.measure(repeats=1, steps=4)
    assert [r["targets"] for r in rows] == [20, 200]
    assert all(math.isclose(r["step_over_reference"], r["reference_per_s"] / r["frames_steps_per_s"]) for r in rows)
    header, cells = _table(perf.report(rows))
    assert header == ["targets", "steps/s with frames", "steps/s detections only", "reference frames/s",
                      "step / reference"]
    assert [c[0] for c in cells] == ["20", "200"] and all(_is_ratio(c[4], c[3], c[1]) for c in cells)
    rows = perf.measure_metrics(repeats=1)
    assert [(r["objects"], r["frames"]) for r in rows] == [(20, 1000), (200, 100)]
    assert all(math.isclose(r["update_over_reference"], r["update_us"] / r["reference_us"]) for r in rows)
    header, cells = _table(perf.report_metrics(rows))
    assert header == ["objects", "frames", "update per frame", "reference per frame", "update / reference",
                      "summary of all frames"]
    assert [c[:2] for c in cells] == [["20", "1000"], ["200", "100"]]
    assert all(_is_ratio(c[4], c[2], c[3]) for c in cells)
    assert all(c[2].endswith(" us") and c[3].endswith(" us") and c[5].endswith(" ms") for c in cells)
    row = perf.measure_metrics_memory(repeats=1, objects=20, frames=300)
    assert 0 < row["kb_per_frame"] < 5 and math.isfinite(row["summary_s"]) and 1 <= row["peak_over_stored"] < 4
    header, cells = _table(perf.report_metrics_memory(row))
    assert header == ["objects", "frames", "stored per frame", "summary", "summary peak / stored"]
    assert cells == [["20", "300", f"{row['kb_per_frame']:.1f} KB", f"{row['summary_s']:.2f} s",
                      f"{row['peak_over_stored']:.2f}x"]]
    rows = perf.measure_pf(repeats=1, frames=2)
    assert [r["tracker"] for r in rows] == ["pf (Li et al. 2007), 1 x 60 particles, 768x576",
                                            "ipf (Liu et al. 2011), 4 x 100 particles, 640x480",
                                            "pf, 30 x 60 particles, mot17_like 960x540",
                                            "ipf, 30 x 100 particles, mot17_like 960x540"]
    header, cells = _table(perf.report_pf(rows))
    assert header == ["tracker", "frames/s", "per-particle calcHist frames/s (its histogram only)",
                      "tracker / reference"]
    assert [c[0] for c in cells] == [r["tracker"] for r in rows] and all(_is_ratio(c[3], c[1], c[2]) for c in cells)


def test_perf_motion_table_has_each_stage_of_each_case():
    rows = perf_motion.measure_motion(repeats=1, steps=2)
    assert [(r["scenario"], r["motion"]) for r in rows] == [c[:2] for c in perf_motion.CASES]
    header, cells = _table(perf_motion.report_motion(rows))
    assert header == ["scenario", "motion", "steps/s", *perf.STAGES] and len(cells) == len(rows)
    assert all(min(r[k] for k in ("world", "render")) > 0 for r in rows)


def test_perf_tables_of_scenarios_scaling_rfs_trackers_and_sweeps():
    rows = perf.measure_scenarios(repeats=1, steps=2)
    assert [r["scenario"] for r in rows] == sorted(scenario.available())
    assert all(math.isclose(r["step_over_reference"], r["reference_per_s"] / r["steps_per_s"]) for r in rows)
    header, cells = _table(perf.report_scenarios(rows))
    assert header == ["scenario", "image", "targets (first frame)", "steps/s", "reference frames/s", "step / reference"]
    assert [c[:3] for c in cells] == [[r["scenario"], r["image"], str(r["targets"])] for r in rows]
    assert ["mot17_like", "960x540"] in [c[:2] for c in cells] and all(_is_ratio(c[5], c[4], c[3]) for c in cells)
    rows = perf.measure_scaling(repeats=1, steps=1)
    assert [(r["targets"], r["image"]) for r in rows] == [(n, size) for size in ("640x480", "1920x1080")
                                                          for n in (20, 200, 2000)]
    assert all(abs(sum(r[k] for k in perf.STAGES) - r["total"]) < 1e-9 and min(r[k] for k in perf.STAGES) >= 0
               for r in rows if r["other"] >= 0)
    text = perf.report_scaling(rows)
    header, cells = _table(text)
    assert header == ["targets", "image", "steps/s", *perf.STAGES] and [c[:2] for c in cells] == [
        [str(r["targets"]), r["image"]] for r in rows]
    assert all(_is_ratio(c[2], "1000", str(r["total"])) for c, r in zip(cells, rows))
    assert "growth, 200 -> 2000 targets (10x) at 640x480: world" in text
    assert "growth, 640x480 -> 1920x1080 (6.75x the pixels) at 200 targets: world" in text
    rows = perf.measure_rfs(repeats=1, frames=3)
    dense = "dense (count=100, pd=0.9, clutter_rate=10.0)"
    assert [(r["tracker"], r["workload"]) for r in rows] == [("gmphd", "mot17_like"), ("gmphd", dense),
                                                             ("lmb:reid=false", dense), ("lmb", dense)]
    assert all(math.isclose(r["over_gnn"], r["ms"] / r["gnn_ms"]) for r in rows)
    assert rows[1]["gnn_ms"] == rows[2]["gnn_ms"] == rows[3]["gnn_ms"]  # one reference per workload
    header, cells = _table(perf.report_rfs(rows))
    assert header == ["tracker", "workload", "ms/frame", "frames/s", "gnn ms/frame", "tracker / gnn"]
    assert [c[:2] for c in cells] == [[r["tracker"], r["workload"]] for r in rows]
    assert all(_is_ratio(c[5], c[2], c[4]) and _is_ratio(c[3], "1000", c[2]) for c in cells)
    row = perf.measure_sweeps(repeats=1, config={"env.max_steps": 3})
    assert row["episodes"] == 24 and math.isclose(row["speedup"], row["one_s"] / row["two_s"])
    header, cells = _table(perf.report_sweeps(row))
    assert header == ["1 worker", "2 workers", "speed-up"] and len(cells) == 1
    assert _is_ratio(cells[0][2], cells[0][0], cells[0][1])


def test_sweep_and_bench_plot_one_panel_per_metric(tmp_path, capsys):
    curve, bars = tmp_path / "curve.png", tmp_path / "bars.png"
    assert cli.main(["sweep", "clutter_storm", "--param", "sensor.clutter_rate=0,20", "--trackers", "sort,iou",
                     "--seeds", "2", "--config", "env.max_steps=10", "--metric", "MOTA,IDF1", "--plot", str(curve)]) == 0
    assert cli.main(["bench", "--scenarios", "clutter_storm,books", "--trackers", "sort,iou", "--seeds", "2",
                     "--config", "env.max_steps=10", "--metric", "MOTA,IDF1,FP", "--plot", str(bars)]) == 0
    assert "plot: " in capsys.readouterr().out
    assert cv2.imread(str(curve)).shape == (456, 1080, 3) and cv2.imread(str(bars)).shape == (456, 1620, 3)


def test_plot_intervals_stop_at_what_the_metric_can_take():
    import numpy as np

    from mtt_sim.lab.plots import clipped_errors

    np.testing.assert_allclose(clipped_errors("IDF1", np.array([0.9, 0.05]), np.array([0.2, 0.2])),
                               [[0.2, 0.05], [0.1, 0.2]])
    np.testing.assert_allclose(clipped_errors("MOTA", np.array([-3.0]), np.array([5.0])), [[5.0], [4.0]])
    np.testing.assert_allclose(clipped_errors("FP", np.array([2.0]), np.array([5.0])), [[2.0], [5.0]])


def test_perf_shows_its_progress_and_prints_each_table(monkeypatch, capsys):
    for module in (perf, perf_motion):
        for name in dir(module):
            if name.startswith("measure"):
                monkeypatch.setattr(module, name, lambda repeats, steps=None, name=name: name)
            elif name.startswith("report"):
                monkeypatch.setattr(module, name, lambda measured: f"table of {measured}")
    assert cli.main(["perf", "--repeats", "1"]) == 0
    captured = capsys.readouterr()
    assert captured.out.count("table of measure") == 12 and "measuring" in captured.err
    assert cli.main(["perf", "--repeats", "1", "--sections", "baselines,jpda"]) == 0
    assert capsys.readouterr().out.split() == ["table", "of", "measure_jpda", "table", "of", "measure_baselines"]
    with pytest.raises(SystemExit):
        cli.main(["perf", "--sections", "speed"])
    assert "'speed': sections are env, scenarios" in capsys.readouterr().err


def test_docs_builds_a_page_per_scenario_and_per_tracker(tmp_path, capsys):
    site = tmp_path / "site"
    assert cli.main(["docs", "--out", str(site)]) == 0
    assert "site: " in capsys.readouterr().out
    landing = (site / "index.html").read_text()  # docs/index.md, not the README: it links the pages
    assert "Find your way" in landing and 'href="jpda/"' in landing and "trackers.register" not in landing
    assert "Fig. 14" in (site / "ipf" / "index.html").read_text()
    for key in scenario.available():
        page = (site / "scenarios" / key / "index.html").read_text()
        assert key in page and (site / "scenarios" / f"{key}.jpg").stat().st_size > 5000
        assert (site / "scenarios" / f"{key}.gif").read_bytes()[:4] == b"GIF8"
    for name in trackers.available():
        assert "Parameters" in (site / "trackers" / docsite.page_name(name) / "index.html").read_text()
    assert "sensor.clutter_rate" in (site / "config" / "index.html").read_text()
    assert cli.main(["docs", "--out", str(site)]) == 2  # there already

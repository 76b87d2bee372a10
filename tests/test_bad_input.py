"""Every subcommand refuses a bad input before any work: exit status 2 and one line naming the argument, file or key
and the value (with a suggestion for a near miss), no traceback, nothing written, no episode run. And --dry-run: every
argument checked as a run checks it, the work estimated in one line, nothing run or written (tests/test_cli.py holds
the first table of bad arguments, BAD_ARGUMENTS)."""

import re

import numpy as np
import pytest

from mtt_sim import cli
from mtt_sim.env import TrackingEnv

from helpers import exit_code, write_sequence

DET = [(f, 10.0 + f, 10.0, 20.0, 40.0, 0.9) for f in range(1, 6)]
GT = [(f, 1, 10.0 + f, 10.0, 20.0, 40.0, 1, 1, 1.0) for f in range(1, 6)]
INFO = "[Sequence]\nname={name}\nimDir=img1\nseqLength=5\nimHeight=80\nimExt=.png\n"


@pytest.fixture(scope="module")
def inputs(tmp_path_factory) -> dict:
    """The files the table names, good and bad, by the word that stands for each in an argv."""
    root = tmp_path_factory.mktemp("inputs")
    found = {}

    def sequence(name, det=DET, gt=GT, files=()):
        folder = write_sequence(root / name, det=det, gt=gt, length=5)
        for path, text in dict(files).items():
            (folder / path).write_text(text)
        found[name.upper()] = str(folder)

    sequence("ok")
    sequence("ok2")
    sequence("emptydet", det=[])
    sequence("emptygt", gt=[])
    sequence("fewcols", files={"det/det.txt": "1,-1,10,10,20\n"})
    sequence("nonnum", files={"det/det.txt": "1,-1,10,10,20,40,0.9,-1,-1,-1\n2,-1,x,10,20,40,0.9,-1,-1,-1\n"})
    sequence("gtbad", files={"gt/gt.txt": "1,1,10,10,20,40,1,1,1\n2,1,10,10\n"})
    sequence("nofr", files={"seqinfo.ini": INFO.format(name="nofr") + "imWidth=100\n"})
    sequence("nowidth", files={"seqinfo.ini": INFO.format(name="nowidth") + "frameRate=10\n"})
    sequence("nosection", files={"seqinfo.ini": "name=nosection\n"})
    for name, text in {"sensor.toml": "[sensor]\npd = 0.8\n", "badsensor.toml": "[sensor]\npdd = 0.5\n",
                       "badsensorval.toml": "[sensor]\npd = 5\n", "typo.toml": 'base = "crossing"\n[sensor]\n'
                       "clutter_rat = 3\n", "results_ok.txt": "1,1,10,10,20,40\n", "results_bad.txt":
                       "1,1,10,10,20,40\n2,1,10,10\n", "results_nonnum.txt": "1,1,10,10,20,40\n2,1,10,y,20,40\n",
                       "badtrace.txt": "0 1 0 0 0 1 0\n1 1 0 x 0 1 0\n",
                       "stilltrace.txt": "0 1 0 0 0 1 0\n1 1 0 0.01 0 1 0\n",
                       "movingtrace.txt": "0 1 0 0 0 1 0\n1 1 0 9.5 0 1 2\n"}.items():
        (root / name).write_text(text)
        found[name.split(".")[0].upper()] = str(root / name)
    np.savez(root / "bad.npz", x=np.zeros(3))
    found["BADNPZ"] = str(root / "bad.npz")
    (root / "data" / "mot15").mkdir(parents=True)
    found["NODATA"] = str(root / "data")
    (root / "site").mkdir()
    (root / "site" / "index.html").write_text("an older site")
    found["SITE"] = str(root / "site")
    return found


CROSSING = ["--scenarios", "crossing", "--trackers", "sort"]
VARY = ["sort", "--scenario", "crossing", "--vary", "sensor.pd=0.5:0.9"]
BAD_INPUTS = [
    # list, trackers
    (["list", "extra"], r"unrecognized arguments: extra"),
    (["trackers", "sortt"], r"unknown tracker 'sortt' \(did you mean 'sort'\?\)"),
    (["trackers", "nowhere.py:Cls"], r"tracker nowhere.py:Cls: no such file 'nowhere.py'"),
    # run: files named with their row or key
    (["run", "OK", "--tracker", "learned:policy=BADNPZ"], r"argument --tracker: policy file \S*bad.npz: not a policy"),
    (["run", "FEWCOLS"], r"fewcols/det/det.txt: row 1 has 5 values, '1,-1,10,10,20'"),
    (["run", "NONNUM"], r"nonnum/det/det.txt: row 2: 'x' is not a number"),
    (["run", "GTBAD"], r"gtbad/gt/gt.txt: row 2 has 4 values"),
    (["run", "NOFR"], r"nofr/seqinfo.ini: \[Sequence\] has no frameRate"),
    (["run", "NOWIDTH"], r"nowidth/seqinfo.ini: \[Sequence\] has no imWidth"),
    (["run", "NOSECTION"], r"nosection/seqinfo.ini: not an INI file with a \[Sequence\] section"),
    (["run", "EMPTYDET"], r"emptydet/det/det.txt: no detection rows: .*--detector synthetic"),
    (["run", "crossing", "--sensor", "BADSENSOR"],
     r"argument --sensor: \S*badsensor.toml: unknown key sensor.pdd \(did you mean sensor.pd\?\)"),
    (["run", "crossing", "--sensor", "BADSENSORVAL"], r"argument --sensor: \S*badsensorval.toml: sensor.pd = 5: out of"),
    (["run", "crossing", "--sensor", "nowhere.toml"], r"argument --sensor: nowhere.toml: no such sensor file"),
    (["run", "TYPO"], r"argument scenario: \S*typo.toml: unknown key sensor.clutter_rat \(did you mean "
                      r"sensor.clutter_rate\?\)"),
    (["run", "crossing", "--config", "render.camera=shake,render.shake=8"],
     r"argument --config: .*render.camera = 'shake,render.shake=8': allowed values: 'static'"),
    (["run", "crossing", "--config", "sensor.pd=0.5", "sensor.pd=0.6"], r"argument --config: sensor.pd is given twice"),
    (["run", "crossing", "--detector", "recorded"], r"argument --config: .*sensor.model = 'recorded' replays"),
    (["run", "OK", "--detector", "foreground"], r"argument --config: \S*ok: sensor.model = 'foreground' needs frames"),
    (["run", "OK", "--config", "sensor.pd=0.5"], r"argument --config: \S*ok: sensor.pd applies to the synthetic"),
    (["run", "crossing", "--scale", "2"], r"argument --scale: 2: enlarges the video's frames; give --video too"),
    # bench
    (["bench", "--scenarios", "EMPTYDET", "--trackers", "sort"], r"emptydet/det/det.txt: no detection rows"),
    ([*["bench", *CROSSING], "--address", "x"], r"argument --address: 'x': a Ray cluster's address goes with --backend"),
    ([*["bench", *CROSSING], "--backend", "rayy"], r"argument --backend: invalid choice: 'rayy'"),
    ([*["bench", *CROSSING], "--config", "sensor.pdd=3"],
     r"argument --config: .*unknown key sensor.pdd \(did you mean sensor.pd\?\)"),
    (["bench", "--scenarios", "crossing,CROSSING", "--trackers", "sort"], r"'crossing,CROSSING': expected distinct"),
    ([*["bench", *CROSSING], "--plot", "p.jpg"], r"argument --plot: 'p.jpg': the file name must end in \.png"),
    ([*["bench", *CROSSING], "--metric", "MOTA,mota"], r"argument --metric: 'MOTA,mota': expected one or more distinct"),
    ([*["bench", *CROSSING], "--results-dir", "/nowhere/x"], r"argument --results-dir: '/nowhere/x': folder '/nowhere'"),
    ([*["bench", *CROSSING], "--seeds", "0-99999999"], r"argument --seeds: '0-99999999': at most 100000 seeds"),
    (["bench", "--scenarios", "books,crossing", "--trackers", "ipf", "--by", "target", "--metric", "CentreError"],
     r"argument --scenarios: books,crossing: --by target makes a column per ground-truth id of one scenario"),
    # sweep
    (["sweep", "crossing", "--param", "sensor.pd=0.5,0.5", "--trackers", "sort"],
     r"argument --param: 'sensor.pd=0.5,0.5': the value 0.5 is given twice"),
    (["sweep", "crossing", "--param", "render.camera=static,shkae", "--trackers", "sort"],
     r"argument --param: .*render.camera = 'shkae': allowed values"),
    (["sweep", "crossing", "--param", "sensor.pdd=0.5,0.6", "--trackers", "sort"],
     r"argument --param: .*unknown key sensor.pdd \(did you mean sensor.pd\?\)"),
    (["sweep", "EMPTYDET", "--param", "env.max_steps=2,3", "--trackers", "sort"], r"emptydet/det/det.txt: no detection"),
    (["sweep", "crossing", "--param", "sensor.pd=0.5,0.7", "--trackers", "sort", "--seeds", "0-x"],
     r"argument --seeds: '0-x': expected a count"),
    # stress
    (["stress", "sort", "--scenario", "crossing", "--vary", "render.camera=static|shkae"],
     r"argument --vary: render.camera=static\|shkae: 'shkae' is not one of render.camera's choices \(did you mean "
     r"'shake'\?\); allowed: static\|pan\|follow\|shake"),
    (["stress", "sort", "--scenario", "OK", "--vary", "sensor.pd=0.5:0.9", "--detector", "synthetic"],
     r"argument --scenario: '\S*ok' is a sequence folder: stress varies a scenario's keys"),
    ([*["stress", *VARY], "--objective", "HOTTA"], r"argument --objective: .*unknown metric 'HOTTA' \(did you mean "
                                                  r"'HOTA'\?\)"),
    (["stress", "sort", "--scenario", "crossing", "--vary", "sensor.pdd=0.5:0.9"], r"argument --vary: sensor.pdd: no "
                                                                                   r"key sensor.pdd"),
    (["stress", "sort", "--scenario", "crossing", "--vary", "sensor.pd=0.9:0.5"], r"argument --vary: sensor.pd=0.9:0.5: "
                                                                                  r"expected LO:HI with LO < HI"),
    (["stress", "sort", "--scenario", "crossing", "--vary", "render.camera"],
     r"argument --vary: render.camera=pan makes no valid scene: .*needs a static or shaking camera"),
    ([*["stress", *VARY], "--budget", "0"], r"argument --budget: must be an integer >= 1, got '0'"),
    ([*["stress", *VARY], "--config", "sensor.pd=2"], r"argument --config: .*sensor.pd = 2: out of range"),
    ([*["stress", *VARY], "--objective", "MOTA[sortt]"], r"argument --objective: unknown tracker 'sortt' \(did you "),
    (["stress", "sort", "--scenario", "TYPO", "--vary", "sensor.pd=0.5:0.9"],
     r"argument --scenario: \S*typo.toml: unknown key sensor.clutter_rat"),
    # tune
    (["tune", "sort", "--on", "crossing", "--metric", "HOTTA"], r"argument --metric: unknown metric 'HOTTA' \(did you "
                                                                r"mean 'HOTA'\?\)"),
    (["tune", "sort", "--on", "EMPTYDET"], r"emptydet/det/det.txt: no detection rows"),
    (["tune", "sort", "--on", "crossing", "--address", "x"], r"argument --address: 'x'"),
    (["tune", "sort", "--on", "crossing", "--trials", "0"], r"argument --trials: must be an integer >= 1, got '0'"),
    (["tune", "sort", "--on", "crossing", "--metric", "HOTA,hota"], r"argument --metric: metrics 'HOTA,hota': one or "
                                                                    r"more, each once"),
    (["tune", "sortt", "--on", "crossing"], r"argument spec: unknown tracker 'sortt' \(did you mean 'sort'\?\)"),
    # fit-scene
    (["fit-scene", "EMPTYDET", "--sensor", "SENSOR", "--out", "s.toml"],
     r"argument DIR: '\S*emptydet/det/det.txt' has no rows"),
    (["fit-scene", "OK", "--sensor", "BADSENSOR", "--out", "s.toml"], r"argument --sensor: \S*badsensor.toml: unknown "
                                                                      r"key sensor.pdd"),
    (["fit-scene", "FEWCOLS", "--sensor", "SENSOR", "--out", "s.toml"],
     r"argument DIR: \S*/fewcols/det/det.txt: row 1 has 5 values"),  # the folder given, no scratch one
    (["fit-scene", "OK", "--sensor", "SENSOR", "--out", "s.txt"], r"argument --out: 's.txt': the file name must end in"),
    (["fit-scene", "nowhere", "--sensor", "SENSOR", "--out", "s.toml"], r"argument DIR: 'nowhere' is not a sequence "),
    # advise
    (["advise", "OK", "--sensor", "BADSENSOR"], r"argument --sensor: \S*badsensor.toml: unknown key sensor.pdd"),
    (["advise", "OK", "--sensor", "SENSOR", "--trackers", "sort,sortt"], r"unknown tracker 'sortt' \(did you mean"),
    (["advise", "OK", "--sensor", "SENSOR", "--out", "a.txt"], r"argument --out: 'a.txt': the file name must end in"),
    (["advise", "OK", "--sensor", "SENSOR", "--resume"], r"argument --resume: needs --out"),
    # learn-policy
    (["learn-policy", "--on", "crossing", "--sigma", "-1"], r"argument --sigma: must be a number > 0, got '-1'"),
    (["learn-policy", "--on", "crossing", "--sigma", "0"], r"argument --sigma: must be a number > 0, got '0'"),
    (["learn-policy", "--on", "crossing", "--sigma", "nan"], r"argument --sigma: must be a number > 0, got 'nan'"),
    (["learn-policy", "--on", "crossing", "--population", "2"], r"argument --population: must be an integer >= 4"),
    (["learn-policy", "--on", "crossing", "--generations", "0"], r"argument --generations: must be an integer >= 1"),
    (["learn-policy", "--on", "crossing", "--frames", "0"], r"argument --frames: must be an integer >= 1, got '0'"),
    (["learn-policy", "--on", "crossing", "--metrics", "MOTA,HOTTA"],
     r"argument --metrics: unknown metric 'HOTTA' \(did you mean 'HOTA'\?\)"),
    (["learn-policy", "--on", "crossing", "--metrics", "FP"], r"argument --metrics: FP: the fitness is a mean of scores"),
    (["learn-policy", "--on", "EMPTYDET"], r"emptydet/det/det.txt: no detection rows"),
    (["learn-policy", "--on", "crossing", "--base", "sortt"], r"argument --base: 'sortt': allowed: sort, bytetrack"),
    (["learn-policy", "--on", "crossing", "--out", "p.txt"], r"argument --out: 'p.txt': the file name must end in"),
    # perf, learn-reid, export
    (["perf", "--steps", "0"], r"argument --steps: must be an integer >= 1, got '0'"),
    (["perf", "--sections", "env,speed"], r"argument --sections: 'env,speed': sections are env, scenarios"),
    (["learn-reid", "--dims", "500"], r"argument --dims: must be an integer in 1..200, got '500'"),
    (["learn-reid", "--scenario", "OK"], r"argument --scenario: '\S*ok' is a sequence folder: crops are rendered"),
    (["export", "EMPTYDET", "--out", "seq"], r"emptydet/det/det.txt: no detection rows"),
    (["export", "crossing", "--out", "seq", "--config", "sensor.pd=2"], r"argument --config: .*sensor.pd = 2: out of"),
    # eval
    (["eval", "--gt", "OK", "--results", "RESULTS_BAD"], r"results_bad.txt: row 2 has 4 values"),
    (["eval", "--gt", "OK", "--results", "RESULTS_NONNUM"], r"results_nonnum.txt: row 2: 'y' is not a number"),
    (["eval", "--gt", "GTBAD", "--results", "RESULTS_OK"], r"gtbad/gt/gt.txt: row 2 has 4 values"),
    (["eval", "--gt", "EMPTYGT", "--results", "RESULTS_OK"], r"emptygt/gt/gt.txt: no rows: there is no ground truth"),
    (["run", "EMPTYGT"], r"emptygt/gt/gt.txt: no rows: nothing to score against"),
    (["tune", "sort", "--on", "EMPTYGT", "--detector", "synthetic"], r"emptygt/gt/gt.txt: no rows: nothing to score"),
    (["eval", "--gt", "OK", "--results", "RESULTS_OK", "--similarity", "giou"], r"argument --similarity: invalid "
                                                                                 r"choice: 'giou'"),
    # check-real
    (["check-real", "/nowhere"], r"argument data: '/nowhere': expected the shared data folder"),
    (["check-real", "NODATA"], r"argument data: '\S*data': mot15/ holds no sequence folder"),
    # calibrate, validate
    (["calibrate", "EMPTYDET", "--out", "s.toml"], r"argument DIR: '\S*emptydet/det/det.txt' has no rows"),
    (["calibrate", "OK", "EMPTYGT", "--out", "s.toml"], r"argument DIR: '\S*emptygt/gt/gt.txt' has no rows"),
    (["calibrate", "NOFR", "--out", "s.toml"], r"argument DIR: \S*nofr/seqinfo.ini: \[Sequence\] has no frameRate"),
    (["calibrate", "NONNUM", "--out", "s.toml"], r"argument DIR: \S*nonnum/det/det.txt: row 2: 'x' is not a number"),
    (["calibrate", "OK", "--out", "s.toml", "--seeds", "0"], r"argument --seeds: must be an integer >= 1, got '0'"),
    (["validate", "EMPTYDET", "OK"], r"argument DIR: '\S*emptydet/det/det.txt' has no rows"),
    (["validate", "OK", "OK2", "--trackers", "sortt"], r"argument --trackers: unknown tracker 'sortt' \(did you mean"),
    (["validate", "GTBAD", "OK"], r"argument DIR: \S*gtbad/gt/gt.txt: row 2 has 4 values"),
    (["validate", "OK", "OK2", "OK"], r"argument DIR: '\S*ok' is given twice; give each sequence once"),
    (["calibrate", "OK", "OK", "--out", "s.toml"], r"argument DIR: '\S*ok' is given twice"),
    # docs, config
    (["docs", "--out", "/nowhere/site"], r"argument --out: '/nowhere/site': folder '/nowhere' does not exist"),
    (["docs", "--out", "SITE"], r"argument --out: '\S*site' exists and is not empty; add --force"),
    (["config", "crossing", "--sensor", "BADSENSOR"], r"argument --sensor: \S*badsensor.toml: unknown key sensor.pdd"),
    (["config", "TYPO"], r"argument scenario: \S*typo.toml: unknown key sensor.clutter_rat"),
    (["config", "socer"], r"argument scenario: unknown scenario 'socer' \(did you mean 'soccer'\?\)"),
    (["config", "--detector", "synthetic"], r"argument --detector: 'synthetic': overrides apply to a scenario"),
    # motion
    (["motion"], r"argument SOURCE: give sequence folders or scenarios, or --trace files"),
    (["motion", "socer"], r"unknown scenario 'socer' \(did you mean 'soccer'\?\)"),
    (["motion", "crossing", "--trace", "BADTRACE"], r"argument --trace: camera trace \S*badtrace.txt, row 2: "
                                                    r"'1 1 0 x 0 1 0' is not numbers"),
    (["motion", "crossing", "--trace-size", "1920"], r"argument --trace-size: expected WIDTHxHEIGHT .*got '1920'"),
    (["motion", "crossing", "--fit", "walk.toml"], r"argument --fit: fits the walking model to real ground truth "
                                                   r"and the camera to traces: give sequence folders"),
    (["motion", "--trace", "STILLTRACE", "MOVINGTRACE", "--fit", "c.toml"], r"argument --fit: the traces mix still "
                                                                         r"cameras \(\S*stilltrace.txt\) and moving"),
    (["motion", "OK", "--fit", "walk.txt"], r"argument --fit: 'walk.txt': the file name must end in \.toml"),
    (["motion", "crossing", "--config", "walk.model=langevn"], r"walk.model = 'langevn': allowed values: 'off', "
                                                                r"'langevin'"),
]


def _argv(argv, inputs):
    """The argv with each word that names an input (OK, BADNPZ, ...) replaced by its path."""
    return [re.sub(r"\b[A-Z][A-Z0-9_]+\b", lambda m: inputs.get(m.group(), m.group()), a) for a in argv]


@pytest.fixture
def no_episode(monkeypatch):
    """Any episode (a reset of the env) fails the test: a refusal comes before any work."""
    def refuse(*args, **kwargs):
        raise AssertionError("an episode started")
    monkeypatch.setattr(TrackingEnv, "reset", refuse)



@pytest.mark.parametrize("argv, pattern", BAD_INPUTS, ids=[" ".join(a) for a, _ in BAD_INPUTS])
def test_a_bad_input_is_refused_in_one_line_naming_it_before_any_work(argv, pattern, inputs, no_episode, capsys,
                                                                      tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code = exit_code(_argv(argv, inputs))
    err = capsys.readouterr().err
    assert code == 2 and re.search(pattern, err), err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert not list(tmp_path.iterdir())  # nothing was written


ISSUE_37 = {"list", "trackers", "run", "bench", "sweep", "stress", "tune", "fit-scene", "learn-policy", "perf", "learn-reid",
            "export", "eval", "check-real", "calibrate", "validate", "docs", "config"}  # the commands it names


def test_the_table_covers_every_subcommand():
    import argparse

    commands = next(a for a in cli.build_parser()._actions if isinstance(a, argparse._SubParsersAction)).choices
    covered = {argv[0] for argv, _ in BAD_INPUTS}
    assert ISSUE_37 <= covered == set(commands) and len(BAD_INPUTS) >= 60


DRY_RUNS = [
    (["run", "crossing", "--compare", "sort,iou", "--steps", "50", "--video", "v.mp4"],
     "run: 2 trackers x 1 seed = 2 episodes, about 100 frames"),
    (["bench", "--trackers", "sort,iou", "--scenarios", "crossing,OK", "--seeds", "3", "--config", "env.max_steps=10",
      "--out", "r.csv"], "bench: 2 trackers x 2 scenarios x 3 seeds = 12 episodes, about 90 frames"),
    (["sweep", "crossing", "--param", "env.max_steps=10,20,30", "--trackers", "sort", "--seeds", "2"],
     "sweep: 1 tracker x 3 values x 2 seeds = 6 episodes, about 120 frames"),
    (["stress", "sort", "--scenario", "crossing", "--vary", "sensor.pd=0.5:0.9", "--objective", "MOTA[iou]-MOTA",
      "--budget", "4", "--config", "env.max_steps=10", "--out", "found"],
     "stress: 4 scenes x 1 seed x 2 trackers = 8 episodes, about 80 frames"),
    (["tune", "sort", "--on", "crossing,OK", "--trials", "3", "--config", "env.max_steps=10", "--out", "b.toml"],
     "tune: 3 trials x 2 sources x 1 seed = 6 episodes, about 45 frames"),
    (["learn-policy", "--on", "EMPTYDET", "--detector", "synthetic", "--generations", "2", "--population", "4",
      "--seeds", "1"], "learn-policy: 2 generations x 4 policies x 1 source x 1 seed = 8 episodes, about 40 frames"),
    (["fit-scene", "OK", "--sensor", "SENSOR", "--out", "s.toml"],
     "fit-scene: 3 runs (the sequence linked, then the scene's seeds) = 3 episodes, about 15 frames"),
    (["advise", "OK", "--sensor", "SENSOR", "--trackers", "sort,iou", "--trials", "3", "--seeds", "2"],
     "advise: 2 trackers x 22 episodes = 44 episodes, about 220 frames, after the scene's fit"),  # 3 x 2 + 4 x 4
    (["perf", "--repeats", "2", "--sections", "env,jpda"], "perf: 2 tables x 2 repeats = 4 measurements"),
    (["learn-reid", "--seeds", "2", "--frames", "30"], "learn-reid: 2 seeds = 2 episodes, about 60 frames"),
    (["export", "crossing", "--out", "seq", "--steps", "7"], "export: 1 episode, about 7 frames"),
    (["eval", "--gt", "OK", "--results", "RESULTS_OK"], "eval: 5 frames scored"),
    (["calibrate", "OK", "OK2", "--out", "s.toml", "--seeds", "2"],
     "calibrate: 2 sequences x 2 seeds = 4 twin runs, about 20 frames"),
    (["validate", "OK", "OK2", "--trackers", "sort", "--seeds", "2"],
     "validate: 2 sequences x 1 tracker x 9 runs (1 real, 4 twins x 2 seeds) = 18 episodes, about 90 frames"),
    (["docs", "--out", "site"], r"docs: \d+ scenarios = \d+ short videos, about \d+ frames"),
]


@pytest.mark.parametrize("argv, estimate", DRY_RUNS, ids=[a[0] for a, _ in DRY_RUNS])
def test_dry_run_checks_estimates_and_writes_nothing(argv, estimate, inputs, no_episode, capsys, tmp_path,
                                                     monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert exit_code([*_argv(argv, inputs), "--dry-run"]) == 0
    out = capsys.readouterr().out
    assert out.strip() == estimate or re.fullmatch(estimate, out.strip()), out
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("argv", [["run", "crossing", "--video", "v.avi"], ["bench", *CROSSING, "--out", "r.txt"],
                                  ["tune", "sort", "--on", "EMPTYDET"], ["calibrate", "OK", "--out", "s.txt"]],
                         ids=lambda argv: argv[0])
def test_a_dry_run_refuses_what_a_run_refuses(argv, inputs, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert exit_code([*_argv(argv, inputs), "--dry-run"]) == 2 and not capsys.readouterr().out


def test_check_real_dry_run_counts_the_sequences(inputs, tmp_path, capsys):
    data = tmp_path / "data"
    write_sequence(data / "mot15" / "Seq", det=DET, gt=GT, length=5)
    assert cli.main(["check-real", str(data), "--dry-run"]) == 0
    assert capsys.readouterr().out.strip() == "check-real: 3 trackers x 1 MOT15 sequence = 3 episodes, about 15 frames"


def test_a_long_run_says_its_estimate_on_stderr_first(capsys):
    assert cli.main(["bench", "--trackers", "sort", "--scenarios", "crossing", "--seeds", "1", "--config",
                     "env.max_steps=3"]) == 0
    captured = capsys.readouterr()
    assert captured.err.startswith("bench: 1 tracker x 1 scenario x 1 seed = 1 episode, about 3 frames\n")
    assert "about 3 frames" not in captured.out


def test_an_empty_det_txt_is_fine_for_the_twin(inputs, capsys):
    assert cli.main(["run", inputs["EMPTYDET"], "--detector", "synthetic", "--json"]) == 0
    assert '"num_frames": 5' in capsys.readouterr().out


def test_calibrate_shows_its_progress(tmp_path, monkeypatch, capsys):
    import tqdm

    bars, real = [], tqdm.tqdm

    def spy(*args, **kwargs):
        bars.append(kwargs)
        return real(*args, **{**kwargs, "disable": True})
    seq = tmp_path / "seq"
    assert cli.main(["export", "mot17_like", "--out", str(seq), "--steps", "40", "--config",
                     "env.obs_mode=detections"]) == 0
    monkeypatch.setattr(tqdm, "tqdm", spy)
    assert cli.main(["calibrate", str(seq), "--out", str(tmp_path / "s.toml"), "--seeds", "2"]) == 0
    assert [b["total"] for b in bars] == [1 + 1 + 2]  # the folder read, the fit, the twin runs
    assert capsys.readouterr().err.count("calibrate: 1 sequence x 2 seeds = 2 twin runs, about 80 frames") == 1

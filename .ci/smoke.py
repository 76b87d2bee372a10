"""Every subcommand of the installed `mtt-sim` once, on tiny inputs this script makes in a temporary folder: the
package users install (a wheel, not the checkout) must run end to end. One line per subcommand with its time; the exit
status is 1 when any failed, or when `mtt-sim --help` lists a subcommand this script does not run.

Run it with the python of an environment where the wheel is installed, from a folder outside the checkout:
    python .ci/smoke.py [--data ../shared/data]
--data: the shared real-data folder for `check-real`, which needs the real sequences and the reference codes'
outputs (a self-made folder cannot stand in for them); without it, `check-real` gets only a folder without mot15/
and must refuse it with its one-line error."""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

TINY = "env.max_steps=20"  # every simulated episode cut to 20 frames


def sequence(folder: Path, seed: int, people: int = 5, frames: int = 60, size=(640, 360)) -> Path:
    """A MOTChallenge sequence folder without images: people walking across, gt/gt.txt (MOT17 columns) and
    det/det.txt (their boxes, noisy, with misses and clutter), seqinfo.ini."""
    rng = np.random.default_rng(seed)
    gt, det = [], []
    for i in range(people):
        h = rng.uniform(60, 120)
        x0, y0, vx = rng.uniform(20, size[0] - 120), rng.uniform(10, size[1] - h - 10), rng.uniform(-2, 2)
        for f in range(1, frames + 1):
            x = float(np.clip(x0 + vx * f, 0, size[0] - 0.4 * h))
            gt.append(f"{f},{i + 1},{x:.2f},{y0:.2f},{0.4 * h:.2f},{h:.2f},1,1,1.0")
            if rng.random() < 0.85:
                bx, by, bw, bh = np.array([x, y0, 0.4 * h, h]) + rng.normal(0, 2, 4)
                det.append(f"{f},-1,{bx:.2f},{by:.2f},{bw:.2f},{bh:.2f},{rng.uniform(0.5, 1):.3f},-1,-1,-1")
    for f in rng.integers(1, frames + 1, frames // 3):
        det.append(f"{f},-1,{rng.uniform(0, 500):.2f},{rng.uniform(0, 250):.2f},30.00,70.00,{rng.uniform(0.2, 0.6):.3f},-1,-1,-1")
    det.sort(key=lambda row: int(row.split(",")[0]))
    for sub, rows in (("gt", gt), ("det", det)):
        (folder / sub).mkdir(parents=True)
        (folder / sub / f"{sub}.txt").write_text("\n".join(rows) + "\n")
    (folder / "seqinfo.ini").write_text(f"[Sequence]\nname={folder.name}\nimDir=img1\nframeRate=10\nseqLength={frames}\n"
                                        f"imWidth={size[0]}\nimHeight={size[1]}\nimExt=.jpg\n")
    return folder


def subcommands(mtt_sim: str) -> list[str]:
    """The subcommands `mtt-sim --help` lists."""
    usage = subprocess.run([mtt_sim, "--help"], capture_output=True, text=True, check=True).stdout
    return re.search(r"\{([a-z,-]+)\}", usage).group(1).split(",")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--data", help="the shared real-data folder for check-real (mot15/, reference/, mot17/, ...)")
    args = parser.parse_args()
    mtt_sim = str(Path(sys.executable).with_name("mtt-sim"))  # the command installed beside this python
    where = subprocess.run([sys.executable, "-c", "import mtt_sim; print(mtt_sim.__file__)"], capture_output=True,
                           text=True, check=True).stdout.strip()
    print(f"smoke: {mtt_sim}, mtt_sim from {where}", flush=True)
    if "site-packages" not in where:
        print(f"FAIL mtt_sim is imported from {where}, not from an installed wheel", flush=True)
        return 1

    tmp = Path(tempfile.mkdtemp(prefix="mtt-sim-smoke-"))
    a, b = sequence(tmp / "Seq-A", seed=1), sequence(tmp / "Seq-B", seed=2, people=4)
    (tmp / "no-data").mkdir()
    data = str(Path(args.data).resolve()) if args.data else None
    t = str(tmp)
    # (subcommand, its arguments, the exit status and the one line of error expected where it must refuse)
    runs = [
        ("list", []),
        ("trackers", []),
        ("config", ["crossing", "--config", "sensor.clutter_rate=3"]),
        ("run", ["crossing", "--tracker", "sort", "--seed", "0", "--steps", "20", "--video", f"{t}/run.gif"]),
        ("run", [str(a), "--tracker", "bytetrack", "--results", f"{t}/results.txt"]),
        ("eval", ["--gt", str(a), "--results", f"{t}/results.txt"]),
        ("bench", ["--trackers", "sort,iou", "--scenarios", "crossing", "--seeds", "1", "--config", TINY,
                   "--out", f"{t}/bench.csv"]),
        ("sweep", ["crossing", "--param", "sensor.clutter_rate=0,5", "--trackers", "sort", "--seeds", "1",
                   "--config", TINY, "--plot", f"{t}/sweep.png"]),
        ("stress", ["sort", "--scenario", "crossing", "--vary", "sensor.pd=0.5:0.95", "--budget", "2", "--seeds", "1",
                    "--top", "1", "--config", TINY, "--out", f"{t}/stress"]),
        ("tune", ["sort", "--on", "crossing", "--trials", "2", "--seeds", "1", "--config", TINY,
                  "--out", f"{t}/best.toml"]),
        ("learn-policy", ["--on", "crossing", "--seeds", "1", "--frames", "20", "--generations", "1",
                          "--population", "4", "--out", f"{t}/policy.npz"]),
        ("learn-reid", ["--scenario", "crossing", "--seeds", "1", "--frames", "20", "--every", "5",
                        "--out", f"{t}/xqda.npz"]),  # never --install: it would write into the installed package
        ("perf", ["--sections", "env", "--repeats", "1", "--steps", "20"]),
        ("export", ["crossing", "--seed", "0", "--steps", "20", "--out", f"{t}/exported"]),
        ("calibrate", [str(a), "--out", f"{t}/fitted.toml", "--seeds", "1"]),
        ("fit-scene", [str(b), "--sensor", f"{t}/fitted.toml", "--out", f"{t}/scene.toml", "--seeds", "1"]),
        ("run", [f"{t}/scene.toml", "--tracker", "sort", "--steps", "20"]),
        ("advise", [str(b), "--sensor", f"{t}/fitted.toml", "--trackers", "sort,iou", "--trials", "2", "--seeds", "1",
                    "--out", f"{t}/advice.md"]),
        ("validate", [str(a), str(b), "--trackers", "sort", "--seeds", "1", "--out", f"{t}/validate.md"]),
        ("motion", [str(a), str(b), "--fit", f"{t}/walkers.toml", "--plot", f"{t}/motion.png"]),
        ("run", ["crossing", "--steps", "20", "--config", "walk.model=langevin", "world.frame_rate=14"]),
        ("check-real", [data]) if data else ("check-real", [f"{t}/no-data"], 2, "expected the shared data folder"),
        # the docs site is built from a source checkout's docs/, which no wheel holds: it must say so in one line
        ("docs", ["--out", f"{t}/site"], 2, "the docs site is built from a source checkout"),
    ]
    failed, ran = [], set()
    for name, argv, *expected in runs:
        code, message = expected or (0, None)
        start = time.perf_counter()
        try:
            done = subprocess.run([mtt_sim, name, *argv], cwd=tmp, capture_output=True, text=True, timeout=300)
            rc, out, err = done.returncode, done.stdout, done.stderr
        except subprocess.TimeoutExpired as e:
            rc, out, err = "timeout", str(e.stdout or ""), str(e.stderr or "")
        seconds = time.perf_counter() - start
        ok = rc == code and (message is None or (message in err and "Traceback" not in err))
        ran.add(name)
        shown = " ".join([name, *argv]).replace(t, "$TMP")
        print(f"{'ok  ' if ok else 'FAIL'} {seconds:6.1f}s  mtt-sim {shown}" + ("" if rc == 0 else f"  (exit {rc})"),
              flush=True)
        if not ok:
            failed.append(name)
            print("     " + "\n     ".join((out + err).strip().splitlines()[-15:]), flush=True)
    missing = [c for c in subcommands(mtt_sim) if c not in ran]
    if missing:
        print(f"FAIL subcommands this smoke does not run: {', '.join(missing)}", flush=True)
    print(f"smoke: {len(runs) - len(failed)} of {len(runs)} runs as expected"
          + (f"; failed: {', '.join(failed)}" if failed else ""), flush=True)
    return 1 if failed or missing else 0


if __name__ == "__main__":
    sys.exit(main())

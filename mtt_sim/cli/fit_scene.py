"""`mtt-sim fit-scene`: a scene fitted to a sequence's detections alone (no labels), its detector from a sensor file;
prints the sequence's statistics beside the scene's own and writes the scene as TOML."""

from __future__ import annotations

import argparse
import shlex
from pathlib import Path

from mtt_sim.cli.arguments import (FORCE_HELP, add_dry_run, check_sensor, dry_run, estimate, integer, output_file,
                                   replaced, rows_in, sequence_read)


def detections_folder(text: str) -> str:
    """A sequence folder with det/det.txt (gt/ is not needed, and not read)."""
    folder = Path(text)
    if not folder.is_dir() or not (folder / "det" / "det.txt").is_file():
        raise argparse.ArgumentTypeError(f"{text!r} is not a sequence folder with det/det.txt"
                                         + (" (no det/det.txt)" if folder.is_dir() else ""))
    rows_in(folder / "det" / "det.txt", "DIR")
    sequence_read(text)
    return text


def add_camera(p) -> None:
    """The camera without labels (DIR) and the detector its scene is seen through (--sensor)."""
    p.add_argument("folder", type=detections_folder, metavar="DIR", help="a sequence folder with det/det.txt")
    p.add_argument("--sensor", required=True, metavar="FILE",
                   help="the detector: a [sensor] table, e.g. from mtt-sim calibrate on other, labelled sequences")


def add(subparsers) -> None:
    p = subparsers.add_parser("fit-scene", help="fit a scene to a sequence's detections alone (no labels): print its "
                                                "statistics beside the scene's and write the scene")
    add_camera(p)
    p.add_argument("--out", required=True, help="the scenario to write (.toml)")
    p.add_argument("--seeds", type=integer(1), default=2, help="scene runs averaged in the check (default 2)")
    p.add_argument("--force", action="store_true", help=FORCE_HELP)
    add_dry_run(p)
    p.set_defaults(func=run)


def run(args) -> int:
    out = output_file(args.out, args.force, "--out", (".toml",))
    check_sensor(args.sensor)
    from mtt_sim.sim2real import fit_scene

    if dry_run(args, estimate("fit-scene", [(1 + args.seeds, "runs (the sequence linked, then the scene's seeds)")],
                              [args.folder], {"sensor.model": "synthetic"})):
        return 0
    _, real, scene, text = fit_scene.fit_scene(args.folder, args.sensor, seeds=tuple(range(args.seeds)))
    print(fit_scene.report(real, scene, Path(args.folder).name))
    out.write_text(text)
    print(f"\nscene: {out}" + replaced(args.force) + f"; tune a tracker on it: mtt-sim tune SPEC --on "
          f"{shlex.quote(str(out))}")
    return 0

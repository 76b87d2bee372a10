"""`mtt-sim docs`: build the documentation site with MkDocs (the [docs] extra)."""

from __future__ import annotations

from pathlib import Path

from mtt_sim.cli.arguments import FORCE_HELP, add_dry_run, dry_run, estimate, output_folder, require


def add(subparsers) -> None:
    p = subparsers.add_parser("docs", help="build the documentation site (MkDocs): the pages under docs/, a page per scenario "
                                           "and per tracker, the configuration reference (the [docs] extra)")
    p.add_argument("--out", required=True, help="the site's folder")
    p.add_argument("--force", action="store_true", help=FORCE_HELP)
    add_dry_run(p)
    p.set_defaults(func=run)


def _gif_frames() -> int:
    from mtt_sim.lab.docsite import GIF_FRAMES

    return GIF_FRAMES


def run(args) -> int:
    out = output_folder(args.out, args.force, "--out", "replace the site")
    require("mkdocs", "docs", "docs")
    require("material", "docs", "docs")
    from mtt_sim.sim import scenario

    keys = list(scenario.available())
    if dry_run(args, estimate("docs", [(len(keys), "scenarios")], keys, unit="short videos",
                              steps=_gif_frames())):
        return 0
    import tempfile

    from mtt_sim.lab import docsite

    with tempfile.TemporaryDirectory() as work:
        docsite.build(out, Path(work))
    print(f"site: {out / 'index.html'}")
    return 0

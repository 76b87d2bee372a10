"""`mtt-sim docs`: the documentation site, built with MkDocs (Material theme). The pages under docs/ are its single
source, docs/index.md its landing page; to them it adds what the code already says: a page per scenario (a still
and a short GIF of the tracker it suits, its description, its TOML file), a page per tracker (its docstring and its
parameters with their ranges and meanings) and the configuration reference. Needs the [docs] extra."""

from __future__ import annotations

import inspect
import json
import shutil
import subprocess
import sys
from importlib import resources
from pathlib import Path

import cv2
import gymnasium as gym

from mtt_sim import trackers

from mtt_sim import env_ids

from mtt_sim.sim import scenario
from mtt_sim.lab.episode import Episode
from mtt_sim.lab.experiment import run_episodes

ROOT = Path(__file__).resolve().parents[2]  # the source checkout
DOCS = ROOT / "docs"  # the site's pages, images and notebooks
# The site's navigation: (title, page under docs/) or (section, [(title, page), ...]). "scenarios/" and "trackers/"
# stand for the generated pages, one per scenario and per tracker, after the section's overview page.
NAV = [("Home", "index.md"),
       ("The Gym loop", "gym.md"),
       ("Trackers", [("Trackers", "trackers.md"), ("One page each", "trackers/"),
                     ("Trackers from parts", "trackers_from_parts.md"),
                     ("Peers: Roboflow's trackers", "peers.md"),
                     ("Camera-motion compensation", "camera_motion.md")]),
       ("Scenarios", [("Scenarios", "scenarios.md"), ("One page each", "scenarios/")]),
       ("Metrics", "metrics.md"),
       ("Configuration", "config.md"),
       ("Command line", "cli.md"),
       ("Tuning", "tuning.md"),
       ("Stress tests", [("Searching for failures", "stress.md"), ("The failure atlas", "failure_atlas.md")]),
       ("Learning", "learning.md"),
       ("Cookbook", "cookbook.md"),
       ("Papers", [("JPDA (Wan, Wang and Yuan 2011)", "jpda.md"),
                   ("Colour and texture particle filter (Li, Zhang and Li 2007)", "colour_pf.md"),
                   ("Interactive particle filter (Liu et al. 2011)", "ipf.md"),
                   ("LMB (Jiang and Yang)", "lmb.md")]),
       ("Real data", [("Real sequences and the digital twin", "real_data.md"),
                      ("The sim-to-real check", "validate.md"),
                      ("How people and cameras move", "motion.md"),
                      ("Detector presets", "detectors.md")]),
       ("Performance", "performance.md"),
       ("Tests", "tests.md")]


def nav_pages() -> list[str]:
    """Every page NAV names, in order ("scenarios/" and "trackers/" for the generated ones)."""
    return [page for _, item in NAV for page in ([item] if isinstance(item, str) else [p for _, p in item])]
GIF_FRAMES = 40
# The trackers each scenario was made for (the papers' scenes) or suits best, the first drawn in its still.
SUITS = {"crossing": ("jpda", "gnn"), "soccer": ("jpda", "gnn"), "umbrellas": ("pf",), "books": ("ipf", "pcpf"),
         "skating": ("ipf", "pf"), "mot17_like": ("lmb", "bytetrack", "sort"), "mot17_moving": ("bytetrack", "sort"),
         "clutter_storm": ("bytetrack", "lmb"), "dense": ("bytetrack", "sort")}


def still(key: str, spec: str, path: Path, frame: int = 30, seed: int = 0, scale: int = 1) -> None:
    """Frame `frame` of scenario `key`'s episode `seed`, with `spec`'s tracks and the drawings it hands to the env,
    enlarged `scale` times, as a JPEG."""
    tracker = trackers.make(spec)
    env = gym.make(env_ids()[key], render_mode="rgb_array", render_scale=scale,
                   obs_mode="frame+detections" if tracker.needs_frame else "detections")
    for now in Episode(env, seed, tracker, steps=frame + 1):
        env.unwrapped.remember_tracks(now.tracks.ids, now.tracks.boxes, tracker.debug(), spec)
    cv2.imwrite(str(path), cv2.cvtColor(env.render(), cv2.COLOR_RGB2BGR), [cv2.IMWRITE_JPEG_QUALITY, 85])
    env.close()


def scenario_page(key: str, folder: Path) -> str:
    suits = SUITS.get(key, ("sort",))
    still(key, suits[0], folder / f"{key}.jpg")
    run_episodes(key, [suits[0]], seed=0, video=str(folder / f"{key}.gif"), steps=GIF_FRAMES)
    toml = resources.files("mtt_sim.scenarios").joinpath(f"{key}.toml").read_text()
    return "\n".join([f"# {key}", "", f"`gym.make(\"{env_ids()[key]}\")`", "", scenario.available()[key], "",
                      f"![{key} with {suits[0]}]({key}.jpg)", "",
                      f"The first {GIF_FRAMES} frames of seed 0 (every other one):", "",
                      f"![{key}, the first frames]({key}.gif)", "",
                      "Suits: " + ", ".join(f"[`{t}`](../trackers/{t}.md)" for t in suits) + ".", "",
                      "Its configuration file (every other key takes its default, see [Configuration](../config.md)):",
                      "", "```toml", toml.rstrip(), "```", ""])


def tracker_page(name: str) -> str:
    cls = trackers.base.REGISTRY[name]
    rows = ["| parameter | default | allowed | meaning |", "|---|---|---|---|"]
    rows += [f"| `{key}` | `{p.default!r}` | {p.allowed_text()} | {p.meaning} |" for key, p in cls.parameters.items()]
    doc = "\n\n".join(" ".join(par.split()) for par in inspect.cleandoc(cls.__doc__ or "").split("\n\n"))
    return "\n".join([f"# {name}", "", f"**{cls.description}**", "", doc, "", "## Parameters", "",
                      f"`trackers.make(\"{name}:key=value,...\")`, or `--trackers '{name}:key=value'` on the "
                      "command line.", "", *rows, ""])


def page_name(tracker: str) -> str:
    """A tracker's page's file name: 'roboflow:sort' -> 'roboflow-sort' (a colon in a link reads as a URL scheme)."""
    return tracker.replace(":", "-")


def nav_lines(keys: list[str], names: list[str]) -> list[str]:
    """NAV as mkdocs.yml lines, the generated pages spelled out: one per scenario `keys`, per tracker `names`."""
    generated = {"scenarios/": [(k, f"scenarios/{k}.md") for k in keys],
                 "trackers/": [(n, f"trackers/{page_name(n)}.md") for n in names]}
    lines = []
    for title, item in NAV:
        if isinstance(item, str):
            lines.append(f"  - {json.dumps(title)}: {item}")
            continue
        lines.append(f"  - {json.dumps(title)}:")
        for sub_title, page in item:
            lines += [f"    - {json.dumps(t)}: {p}" for t, p in generated.get(page, [(sub_title, page)])]
    return lines


def write_sources(folder: Path) -> None:
    """The site's Markdown, images and mkdocs.yml under `folder` (the MkDocs project): a copy of docs/, the
    generated pages beside it, and the configuration reference from the code (docs/config.md is its copy)."""
    docs = folder / "docs"
    shutil.copytree(DOCS, docs, dirs_exist_ok=True, ignore=shutil.ignore_patterns("__pycache__"))
    for sub in ("scenarios", "trackers"):
        (docs / sub).mkdir(parents=True, exist_ok=True)
    (docs / "config.md").write_text("# Configuration\n\n" + scenario.reference_table() + "\n")
    keys = sorted(scenario.available())
    for key in keys:
        (docs / "scenarios" / f"{key}.md").write_text(scenario_page(key, docs / "scenarios"))
    names = sorted(trackers.base.REGISTRY)
    for name in names:
        (docs / "trackers" / f"{page_name(name)}.md").write_text(tracker_page(name))
    (folder / "mkdocs.yml").write_text("\n".join(["site_name: mtt-sim", "theme:", "  name: material", "nav:",
                                                  *nav_lines(keys, names), ""]))


def build(out: Path, work: Path) -> None:
    """Write the sources into `work` and build the site into `out`."""
    try:
        import material  # noqa: F401  (the theme)
        import mkdocs  # noqa: F401
    except ImportError:
        raise ImportError("the docs site needs MkDocs: pip install 'mtt-sim[docs]'") from None
    if not (DOCS / "index.md").is_file():
        raise FileNotFoundError(f"the docs site is built from a source checkout: no docs/index.md in {ROOT}")
    write_sources(work)
    done = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--quiet", "--config-file",
                           str(work / "mkdocs.yml"), "--site-dir", str(Path(out).resolve())],
                          capture_output=True, text=True)
    if done.returncode:
        raise OSError(f"mkdocs build failed:\n{done.stderr[-2000:]}")  # the external tool failed, as a file would

"""The documentation stays true: the README is a short front door, the pages under docs/ hold the rest, their links
lead somewhere, their Python examples run, and the generated parts match the code."""

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

import mtt_sim
from mtt_sim.lab import docsite
from mtt_sim.sim import scenario

ROOT = Path(__file__).resolve().parent.parent
README = ROOT / "README.md"
DOCS = ROOT / "docs"
PAGES = sorted(DOCS.glob("*.md"))
SETUP = ["python3 -m pip install . && mtt-sim run crossing --tracker sort --seed 0 --steps 300",
         'python3 -m pip install -e ".[test]" && pytest']


def test_config_reference_is_current():
    text = (ROOT / "docs" / "config.md").read_text()
    assert scenario.reference_table() in text, "regenerate docs/config.md with `mtt-sim config` (see its header)"


def test_readme_lists_every_scenario():
    readme = README.read_text()
    for key in scenario.available():
        assert f"`{key}`" in readme


def test_scenarios_page_has_a_row_per_scenario_with_its_env_id():
    rows = re.findall(r"^\| `(\w+)` \| `(mtt_sim/\w+-v0)` \|", (DOCS / "scenarios.md").read_text(), re.M)
    assert dict(rows) == mtt_sim.env_ids() and len(rows) == len(mtt_sim.env_ids())


def test_readme_is_a_front_door_of_at_most_300_lines_starting_with_the_two_setup_commands():
    lines = README.read_text().splitlines()
    assert len(lines) <= 300, f"README.md has {len(lines)} lines: move detail to a page under docs/"
    assert lines[:6] == ["# mtt-sim", "", "```", *SETUP, "```"]
    assert lines[7].startswith("The first installs the package and runs SORT")


# ---------------------------------------------------------------------------------------------------- links

def without_blocks(text: str) -> str:
    """Markdown without its fenced code blocks."""
    return re.sub(r"^```.*?^```", "", text, flags=re.S | re.M)


def without_code(text: str) -> str:
    """Markdown without its code blocks and inline code spans: links there are examples, not links."""
    return re.sub(r"`[^`\n]*`", "", without_blocks(text))


def links(text: str) -> list[tuple[str, str]]:
    """The (path, anchor) of every relative link and image in Markdown `text`; web and mail links are left out."""
    out = []
    for target in re.findall(r"\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)", without_code(text)):
        if not re.match(r"^[a-z]+:", target):
            path, _, anchor = target.partition("#")
            out.append((path, anchor))
    return out


def anchors(text: str) -> set[str]:
    """The anchors of a page's headings, as GitHub makes them and as MkDocs makes them (both must reach them)."""
    out = set()
    for title in re.findall(r"^#+ (.+)$", without_blocks(text).replace("`", ""), re.M):
        github = re.sub(r"[^\w\- ]", "", title.strip().lower()).replace(" ", "-")
        mkdocs = re.sub(r"[-\s]+", "-", re.sub(r"[^\w\s-]", "", title).strip().lower())
        out.add(github if github == mkdocs else f"{github} (MkDocs: {mkdocs})")
    return out


def test_links_and_anchors_are_read_as_markdown_means_them():
    text = "# A `b`: c\n\n## d - e\n\nSee [x](p.md#a-b-c), ![i](i.png) and [w](https://x.org).\n`[no](n.md)`\n" \
           "```\n[no](m.md)\n```\n"
    assert links(text) == [("p.md", "a-b-c"), ("i.png", "")]
    assert anchors(text) == {"a-b-c", "d---e (MkDocs: d-e)"}
    assert ("docs/jpda.md", "") in links(README.read_text())


@pytest.mark.parametrize("path", [README, *PAGES], ids=lambda p: p.relative_to(ROOT).as_posix())
def test_every_relative_link_leads_to_a_file_and_heading_that_exist(path):
    """README.md's links may go anywhere in the checkout; a page's must stay under docs/, the site's one source."""
    text = path.read_text()
    for target, anchor in links(text):
        file = (path.parent / target).resolve() if target else path
        assert file.exists(), f"{path.name}: link to {target!r}: no such file"
        if path.parent == DOCS:
            assert file.is_relative_to(DOCS), f"{path.name}: link to {target!r} leaves docs/, which the site holds"
        if anchor and file.suffix == ".md":
            assert anchor in anchors(file.read_text()), f"{path.name}: link to {target}#{anchor}: no such heading"


# ---------------------------------------------------------------------------------------------------- examples

RUNNER = r"""
import re, sys, traceback
path = sys.argv[1]
blocks = re.findall(r"^```python\n(.*?)^```", open(path).read(), re.S | re.M)
for n, code in enumerate(blocks, 1):
    try:  # each example on its own, as a reader would paste it
        exec(compile(code, f"{path}, example {n}", "exec"), {"__name__": "__main__"})
    except BaseException:
        traceback.print_exc()
        sys.exit(f"{path}: example {n} of {len(blocks)} failed")
print(f"{len(blocks)} examples ran")
"""
# abewley/sort's Sort, for the example that runs it through trackers.External: each detection a track, in order
STAND_IN_SORT = '''import numpy as np
class Sort:
    def __init__(self, max_age=1, min_hits=3):
        pass
    def update(self, dets=np.empty((0, 5))):
        return np.column_stack([dets[:, :4], np.arange(1, len(dets) + 1)])
'''
WITH_EXAMPLES = [p for p in [README, *PAGES] if "```python\n" in p.read_text()]


def test_the_readme_and_the_pages_that_teach_have_examples():
    names = {p.name for p in WITH_EXAMPLES}
    assert {"README.md", "gym.md", "trackers.md", "metrics.md", "cookbook.md"} <= names


@pytest.mark.parametrize("path", WITH_EXAMPLES, ids=lambda p: p.relative_to(ROOT).as_posix())
def test_python_examples_run(path, tmp_path):
    """Every ```python block of the README and of the pages runs, each in a fresh namespace, in a fresh process
    (an example that registers a tracker leaves the registry of this one alone)."""
    (tmp_path / "sort.py").write_text(STAND_IN_SORT)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path), os.environ.get("PYTHONPATH", "")])}
    done = subprocess.run([sys.executable, "-c", RUNNER, str(path)], capture_output=True, text=True, env=env,
                          cwd=tmp_path, timeout=600)
    count = path.read_text().count("```python\n")
    assert done.returncode == 0 and f"{count} examples ran" in done.stdout, done.stdout[-3000:] + done.stderr[-3000:]


# ---------------------------------------------------------------------------------------------------- the site

def test_the_site_navigation_lists_every_page_once():
    named = docsite.nav_pages()
    assert len(named) == len(set(named))
    assert set(named) == {p.name for p in PAGES} | {"scenarios/", "trackers/"}
    assert named[0] == "index.md"


def test_the_site_navigation_spells_out_a_page_per_scenario_and_per_tracker():
    lines = docsite.nav_lines(["crossing", "dense"], ["sort"])
    assert '  - "Home": index.md' in lines and '    - "crossing": scenarios/crossing.md' in lines
    assert lines.index('    - "Scenarios": scenarios.md') + 1 == lines.index('    - "crossing": scenarios/crossing.md')
    assert '    - "sort": trackers/sort.md' in lines and not any("One page each" in line for line in lines)

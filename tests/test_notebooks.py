"""The notebooks under docs/notebooks are those the docs link to, are committed without outputs, use public names
only, and run top to bottom: their code cells, in order, as one script in a fresh process (what a reader gets from
'Run all'), with matplotlib's non-interactive backend."""

import ast
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
NOTEBOOKS = sorted((ROOT / "docs" / "notebooks").glob("*.ipynb"))


def test_every_notebook_the_docs_link_to_is_here_and_every_one_here_is_linked():
    """NOTEBOOKS is whatever the folder holds, so a missing notebook would only drop its cases from the tests below:
    the docs' links say which must be there."""
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    linked = {name for page in pages for name in re.findall(r"notebooks/([\w-]+\.ipynb)", page.read_text())}
    assert linked == {p.name for p in NOTEBOOKS}


@pytest.mark.parametrize("notebook", NOTEBOOKS, ids=lambda p: p.stem)
def test_notebook_is_committed_clean_and_uses_public_names(notebook):
    """No outputs or run counts (a reader sees what the code gives today, not a stale run), and no `_private` name:
    a notebook shows the API a user may rely on."""
    cells = json.loads(notebook.read_text())["cells"]
    assert all(not c.get("outputs") and c.get("execution_count") is None for c in cells if c["cell_type"] == "code")
    code = ast.parse("\n\n".join("".join(c["source"]) for c in cells if c["cell_type"] == "code"))
    names = [n.attr for n in ast.walk(code) if isinstance(n, ast.Attribute)]
    names += [part for n in ast.walk(code) if isinstance(n, ast.ImportFrom) for part in (n.module or "").split(".")]
    names += [part for n in ast.walk(code) if isinstance(n, (ast.Import, ast.ImportFrom)) for a in n.names
              for part in a.name.split(".")]
    private = [name for name in names if name.startswith("_") and not name.startswith("__")]
    assert not private, private


@pytest.mark.parametrize("notebook", NOTEBOOKS, ids=lambda p: p.stem)
def test_notebook_runs_top_to_bottom(notebook, tmp_path):
    cells = json.loads(notebook.read_text())["cells"]
    script = "\n\n".join("".join(c["source"]) for c in cells if c["cell_type"] == "code")
    done = subprocess.run([sys.executable, "-c", script], cwd=tmp_path, capture_output=True, text=True, timeout=300,
                          env={**os.environ, "MPLBACKEND": "Agg"})
    assert done.returncode == 0, done.stderr[-3000:]

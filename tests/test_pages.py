"""What the pages are made of: validate's Markdown tables and the learning curve's axis."""

from __future__ import annotations

import re
from types import SimpleNamespace

import numpy as np
import pytest

from mtt_sim.sim2real import validate


def _cells(line: str) -> list[str]:
    """A Markdown table row's cells, split at every `|` that is not escaped."""
    return re.split(r"(?<!\\)\|", line.strip())[1:-1]


def _tables(text: str) -> list[list[str]]:
    tables, block = [], []
    for line in text.splitlines() + [""]:
        if line.startswith("|"):
            block.append(line)
        elif block:
            tables.append(block)
            block = []
    return tables


def _validation() -> validate.Validation:
    """Two sequences, two trackers, every twin: made-up numbers, shaped as `validate.validate` returns them."""
    seqs, trs = ("Seq|0", "Seq1"), ("sort", "iou")
    real = {(s, t): {"MOTA": 0.5, "IDF1": 0.6, "IDSW": 3.0} for s in seqs for t in trs}
    twin = {(w.name, s, t): {"MOTA": 0.4, "IDF1": 0.7, "IDSW": 5.0} for w in validate.TWINS for s in seqs for t in trs}
    stats = dict.fromkeys(validate.DETECTOR_STATISTICS, 0.5)
    detector = {(s, k): stats for s in seqs for k in ("data", *(w.name for w in validate.TWINS))}
    return validate.Validation(seqs, trs, validate.TWINS, real, twin, detector, 2, ())


def test_validate_tables_escape_bars_so_every_row_has_the_header_s_cells():
    text = validate.markdown(_validation())
    tables = _tables(text)
    assert len(tables) == 5  # the summary, MOTA, IDF1, IDSW, the detector statistics
    for table in tables:
        assert len({len(_cells(line)) for line in table}) == 1, table
    assert r"| P(miss \| miss) |" in text and r"| Seq\|0 |" in text
    assert validate.row("a|b", 1) == r"| a\|b | 1 |"


def test_validate_page_tables_have_as_many_cells_in_every_row():
    from pathlib import Path

    page = (Path(__file__).parents[1] / "docs" / "validate.md").read_text()
    for table in _tables(page):
        assert len({len(_cells(line)) for line in table}) == 1, table


@pytest.mark.parametrize("generations", [1, 3, 7, 25])
def test_learning_curve_ticks_only_whole_generations(generations, tmp_path, monkeypatch):
    pytest.importorskip("matplotlib")
    from mtt_sim.lab import plots

    figures = []
    real_save = plots._save
    monkeypatch.setattr(plots, "_save", lambda plt, fig, path: (figures.append(fig), real_save(plt, fig, path)))
    best = np.linspace(0.5, 0.7, generations)
    learning = SimpleNamespace(episodes=4, best_so_far=best, generation_mean=best - 0.1, start_fitness=0.5)
    plots.learning_curve(learning, tmp_path / "curve.png")
    (ax,) = figures[0].axes
    lo, hi = ax.get_xlim()
    ticks = [t for t in ax.get_xticks() if lo <= t <= hi]
    assert ticks and all(float(t).is_integer() for t in ticks), ticks
    assert (tmp_path / "curve.png").stat().st_size > 0

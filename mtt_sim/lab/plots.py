"""Plots of bench and sweep records: one panel per metric, the mean and its 95 % interval over seeds, each interval
clipped to the values its metric can take. Needs matplotlib (the [plot] extra)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Sequence

import numpy as np

from mtt_sim.lab.experiment import summarize

# The values each metric can take (an interval reaching past them says nothing): ratios in [0, 1], MOTA and MODA
# at most 1, everything else (counts, distances, GOSPA) at least 0.
_RATIOS = {"MOTP", "CLR_Re", "CLR_Pr", "IDF1", "IDP", "IDR", "HOTA", "DetA", "AssA", "LocA", "DetRe", "DetPr", "AssRe",
           "AssPr", "HOTA(0)", "LocA(0)", "Coverage"}


def metric_range(metric: str) -> tuple[float, float]:
    if metric in _RATIOS:
        return 0.0, 1.0
    return (-math.inf, 1.0) if metric in ("MOTA", "MODA") else (0.0, math.inf)


def clipped_errors(metric: str, mean: np.ndarray, ci: np.ndarray) -> np.ndarray:
    """(2, n) lower and upper error-bar lengths of mean ± ci, cut at the metric's range."""
    lo, hi = metric_range(metric)
    return np.stack([mean - np.maximum(mean - ci, lo), np.minimum(mean + ci, hi) - mean])


def _pyplot():
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise ImportError("plots need matplotlib: pip install 'mtt-sim[plot]'") from None
    return plt


def _panels(metrics: Sequence[str], title: str):
    plt = _pyplot()
    fig, axes = plt.subplots(1, len(metrics), figsize=(4.5 * len(metrics), 3.8), squeeze=False)
    fig.suptitle(title)
    return plt, fig, axes[0]


def _save(plt, fig, path: str | Path) -> None:
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def _seeds(records: Sequence[dict]) -> int:
    return len({r["seed"] for r in records})


def sweep_plot(records: Sequence[dict], scenario: str, param: str, values: Sequence, metrics: Sequence[str],
               path: str | Path) -> None:
    """Stress curves: each metric against the swept value, one line per tracker."""
    plt, fig, axes = _panels(metrics, f"{scenario}, sweeping {param}: mean and 95 % interval over "
                                      f"{_seeds(records)} seeds")
    for ax, metric in zip(axes, metrics):
        rows = summarize(records, metric, by="config")
        for tracker in dict.fromkeys(r["tracker"] for r in rows):
            mine = [r for r in rows if r["tracker"] == tracker]
            mean, ci = np.array([r["mean"] for r in mine]), np.array([r["ci95"] for r in mine])
            ax.errorbar([str(v) for v in values], mean, yerr=clipped_errors(metric, mean, ci), marker="o", capsize=3,
                        label=tracker)
        ax.set_xlabel(param)
        ax.set_ylabel(metric)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize="small")
    _save(plt, fig, path)


def bench_plot(records: Sequence[dict], metrics: Sequence[str], path: str | Path) -> None:
    """Bars: each metric per scenario, one bar per tracker, with its interval."""
    scenarios = list(dict.fromkeys(r["column"] for r in summarize(records, metrics[0])))
    plt, fig, axes = _panels(metrics, f"{', '.join(scenarios)}: mean and 95 % interval over {_seeds(records)} seeds")
    for ax, metric in zip(axes, metrics):
        rows = summarize(records, metric)
        trackers = list(dict.fromkeys(r["tracker"] for r in rows))
        width = 0.8 / len(trackers)
        for k, tracker in enumerate(trackers):
            cell = {r["column"]: r for r in rows if r["tracker"] == tracker}
            mean = np.array([cell[s]["mean"] if s in cell else np.nan for s in scenarios])
            ci = np.array([cell[s]["ci95"] if s in cell else 0.0 for s in scenarios])
            ax.bar(np.arange(len(scenarios)) + (k - (len(trackers) - 1) / 2) * width, mean, width,
                   yerr=clipped_errors(metric, mean, ci), capsize=3, label=tracker)
        ax.set_xticks(np.arange(len(scenarios)), scenarios)
        ax.set_ylabel(metric)
        ax.grid(alpha=0.3, axis="y")
    axes[0].legend(fontsize="small")
    _save(plt, fig, path)


def learning_curve(learning, path: str | Path) -> None:
    """A policy search's fitness per generation: the best so far and the generation's mean, over SORT's rules."""
    n = learning.episodes
    plt, fig, (ax,) = _panels(["fitness"], f"learning from the score: {n} training episode{'s' * (n != 1)}")
    from matplotlib.ticker import MaxNLocator
    gens = np.arange(1, len(learning.best_so_far) + 1)
    ax.plot(gens, learning.best_so_far, "o-", label="best so far")
    ax.plot(gens, learning.generation_mean, ".", color="0.5", label="generation mean")
    ax.axhline(learning.start_fitness, color="C3", ls="--", label="SORT's rules (the start)")
    ax.set(xlabel="generation", ylabel="fitness")
    ax.set_xlim(0.5, len(gens) + 0.5)
    ax.xaxis.set_major_locator(MaxNLocator(integer=True, min_n_ticks=1))  # generations are whole: no tick at 1.5
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small")
    _save(plt, fig, path)

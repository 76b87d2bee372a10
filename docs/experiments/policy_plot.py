"""What a `learned` policy decides, drawn: the report decision of a matched candidate over its hits (streak alike)
and its detection's confidence, and the keep decision over its misses and its hits (age alike), the other features
held at typical values; SORT's rules beside it.

    python docs/experiments/policy_plot.py OUT.png [POLICY.npz]
"""

import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from mtt_sim.trackers.learned import SHIPPED_POLICY, load_policy
from mtt_sim.trackers.parts.management import FEATURES, SORT_RULES

TYPICAL = {"confidence": 0.8, "match_iou": 0.7, "height": 0.15, "aspect": 0.1, "growth": 0.0, "speed": 0.05,
           "overlap": 0.0, "border": 1.0}


def grid(weights, row, xs, ys, fill):
    """The score of decision `row` over a grid: fill(features, x, y) sets the two varied features."""
    score = np.zeros((len(ys), len(xs)))
    for i, y in enumerate(ys):
        for j, x in enumerate(xs):
            f = np.zeros(len(FEATURES))
            for k, v in TYPICAL.items():
                f[FEATURES.index(k)] = v
            fill(f, x, y)
            score[i, j] = f @ weights[row, :-1] + weights[row, -1]
    return score


def main() -> None:
    policy = load_policy(sys.argv[2] if len(sys.argv) > 2 else SHIPPED_POLICY)
    hits, conf, misses = np.arange(0, 11), np.linspace(0.3, 1.0, 15), np.arange(0, 11)
    c = {k: FEATURES.index(k) for k in FEATURES}

    def report(f, h, cf):
        f[[c["matched"], c["streak"], c["hits"], c["age"], c["confidence"]]] = 1, h / 10, h / 10, h / 10, cf

    def keep(f, m, h):
        f[[c["streak"], c["hits"], c["age"], c["misses"]]] = 0, h / 10, (h + m) / 10, m / 10

    fig, axes = plt.subplots(2, 2, figsize=(9, 6.5), layout="constrained")
    for col, (name, weights) in enumerate((("SORT's rules", SORT_RULES), ("learned (shipped)", policy))):
        for row, (title, xs, ys, fill, xl, yl) in enumerate((
                ("report a matched candidate?", hits, conf, report, "hits in a row", "detection confidence"),
                ("keep a missed candidate?", misses, hits, keep, "frames missed", "hits before the misses"))):
            ax = axes[row, col]
            score = grid(weights, row, xs, ys, fill)
            ax.pcolormesh(xs, ys, score > 0, cmap="RdYlGn", vmin=-0.3, vmax=1.3, shading="nearest")
            ax.contour(xs, ys, score, levels=[0], colors="k", linewidths=1)
            ax.set(title=f"{name}: {title}", xlabel=xl, ylabel=yl)
    fig.suptitle("green: yes, red: no (other features at typical values)")
    fig.savefig(sys.argv[1], dpi=100)


if __name__ == "__main__":
    main()

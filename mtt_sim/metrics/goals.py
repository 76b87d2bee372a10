"""Which way each metric is better, and a list of metrics to optimise read from text such as 'HOTA,-IDSW'."""

from __future__ import annotations

import difflib
from dataclasses import dataclass

from mtt_sim.metrics.episode import METRICS, SUMMARY_FIELDS

LOWER_IS_BETTER = {f.name for f in SUMMARY_FIELDS if f.lower_is_better}  # counts of errors, distances; the rest higher


@dataclass(frozen=True)
class Goal:
    """One metric to optimise and its direction."""

    metric: str
    maximize: bool

    @property
    def text(self) -> str:
        return self.metric if self.maximize != (self.metric in LOWER_IS_BETTER) else \
            ("+" if self.maximize else "-") + self.metric


def goals(text: str) -> list[Goal]:
    """'HOTA' or 'HOTA,-IDSW': each metric in its natural direction (higher is better but for counts of errors and
    distances), or as its sign says."""
    names = {m.lower(): m for m in METRICS}
    out = []
    for item in filter(None, (i.strip() for i in text.split(","))):
        sign, name = (item[0], item[1:]) if item[0] in "+-" else ("", item)
        if name.lower() not in names:
            near = difflib.get_close_matches(name.lower(), names, n=1)
            raise ValueError(f"unknown metric {name!r}" + (f" (did you mean {names[near[0]]!r}?)" if near else "")
                             + f"; available: {', '.join(METRICS)}")
        metric = names[name.lower()]
        out.append(Goal(metric, sign == "+" or (not sign and metric not in LOWER_IS_BETTER)))
    if not out or len({g.metric for g in out}) != len(out):
        raise ValueError(f"metrics {text!r}: one or more, each once, e.g. HOTA or HOTA,-IDSW")
    return out

"""The MOTChallenge sequence folder: what makes a folder one (kept apart so that naming a source stays cheap)."""

from __future__ import annotations

from pathlib import Path

MARKERS = ("seqinfo.ini", "det/det.txt", "gt/gt.txt")


def is_sequence(path) -> bool:
    """Whether `path` is a folder laid out as a MOTChallenge sequence (seqinfo.ini, det/det.txt or gt/gt.txt)."""
    p = Path(path)
    return p.is_dir() and any((p / f).is_file() for f in MARKERS)

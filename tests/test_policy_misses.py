"""docs/experiments/policy_misses.py: what a missed track means, counted on hand-made sequences with known answers."""

import importlib.util

import numpy as np

from helpers import EXPERIMENTS, write_sequence
from mtt_sim.trackers.learned import load_policy
from mtt_sim.trackers.parts.management import FEATURES

spec = importlib.util.spec_from_file_location("policy_misses", EXPERIMENTS / "policy_misses.py")
policy_misses = importlib.util.module_from_spec(spec)
spec.loader.exec_module(policy_misses)

KEEP_ALL = np.zeros((2, len(FEATURES) + 1))
KEEP_ALL[:, -1] = 1.0  # report and keep every candidate, whatever its features


def gt(frame, person, box):
    return (frame, person, *box, 1, 1, 1.0)


def test_a_person_walking_out_at_the_border_is_gone_at_the_border(tmp_path):
    boxes = {f: (82.0 + 2 * f, 30.0, 10.0, 20.0) for f in range(1, 5)}  # frame 4: right edge at the image's (100)
    folder = write_sequence(tmp_path / "s", det=[(f, *b, 1.0) for f, b in boxes.items()],
                            gt=[gt(f, 1, b) for f, b in boxes.items()], length=6)
    m = policy_misses.misses(str(folder), load_policy("sort_rules"))
    assert (m["first misses"], m["gone"], m["gone at the border"], m["late matches"]) == (1, 1.0, 1.0, 0)


def test_a_late_match_takes_its_own_person_or_another(tmp_path):
    one, two = (40.0, 30.0, 10.0, 20.0), (10.0, 30.0, 10.0, 20.0)
    # person 1 stands and is missed in frames 4-5; person 2 leaves after frame 3 (away from the border), and in frame
    # 6 person 3 stands where person 2 stood
    det = [(f, *b, 1.0) for f in (1, 2, 3) for b in (one, two)] + [(6, *one, 1.0), (6, *two, 1.0)]
    truth = ([gt(f, 1, one) for f in range(1, 7)] + [gt(f, 2, two) for f in (1, 2, 3)] + [gt(6, 3, two)])
    folder = write_sequence(tmp_path / "s", det=det, gt=truth)
    m = policy_misses.misses(str(folder), KEEP_ALL)
    assert (m["first misses"], m["gone"], m["gone at the border"]) == (2, 0.5, 0.0)
    assert (m["late matches"], m["own"], m["another"], m["nobody"]) == (2, 0.5, 0.5, 0.0)
    # with SORT's rules a track missed twice is dropped: no late match
    assert policy_misses.misses(str(folder), load_policy("sort_rules"))["late matches"] == 0

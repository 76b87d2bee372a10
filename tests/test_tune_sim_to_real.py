"""docs/experiments/tune_sim_to_real.py: a tuned spec is scored on the real sequence, however many tracks it reports."""

import importlib.util
import math

import pytest

from helpers import EXPERIMENTS, write_sequence
from mtt_sim.lab.experiment import run_episode

spec = importlib.util.spec_from_file_location("tune_sim_to_real", EXPERIMENTS / "tune_sim_to_real.py")
tune_sim_to_real = importlib.util.module_from_spec(spec)
spec.loader.exec_module(tune_sim_to_real)


def test_a_spec_reporting_more_tracks_than_the_action_rows_is_scored_not_stopped(tmp_path):
    """One person in two frames, detected, with 299 small clutter boxes around: `echo` reports 300 tracks a frame,
    more than the env's 256 action rows. Scored, its HOTA is sqrt(DetA * AssA) = sqrt(2 / 600 * 1)."""
    person = (300.0, 320.0, 20.0, 40.0)
    clutter = [(20.0 * (i % 20), 20.0 * (i // 20), 5.0, 5.0) for i in range(299)]
    det = [(f, *box, score) for f in (1, 2) for box, score in [(person, 1.0), *((c, 0.5) for c in clutter)]]
    folder = write_sequence(tmp_path / "seq", det=det, gt=[(f, 1, *person, 1, 1, 1.0) for f in (1, 2)],
                            size=(400, 400))
    with pytest.raises(ValueError, match="256 rows"):
        run_episode(str(folder), "echo")
    assert tune_sim_to_real._real(folder, "echo", "HOTA") == pytest.approx(math.sqrt(1 / 300))

"""docs/experiments/scene_people.py: who is scored and where people leave, on hand-made frames and a tiny sequence."""

import importlib.util

import numpy as np
import pytest

from helpers import EXPERIMENTS, write_sequence

spec = importlib.util.spec_from_file_location("scene_people", EXPERIMENTS / "scene_people.py")
scene_people = importlib.util.module_from_spec(spec)
spec.loader.exec_module(scene_people)


def frame(*people):
    """One frame's (ids, boxes, visibility) from (id, x, y, w, h, visibility) tuples."""
    rows = np.array(people, float).reshape(-1, 6)
    return rows[:, 0].astype(int), rows[:, 1:5], rows[:, 5]


def test_people_who_end_inside_the_picture_are_told_from_those_who_walk_out():
    # person 1 stays to the last frame; person 2 ends inside (20 px tall, wholly hidden in its last frame); person 3
    # ends touching the left border (30 px tall): of the two who end, one ends inside
    frames = [frame((1, 40, 20, 10, 40, 1.0), (2, 60, 30, 8, 20, 1.0), (3, 0, 30, 10, 30, 0.5)),
              frame((1, 42, 20, 10, 40, 1.0), (2, 60, 30, 8, 20, 0.0)),
              frame((1, 44, 20, 10, 40, 1.0))]
    got = scene_people.measure(frames, (100, 80))
    assert got["hidden"] == pytest.approx(1 / 6) and got["ended"] == 2
    assert got["inside"] == 0.5 and got["last"] == 25.0
    assert got["p95"] == pytest.approx(np.percentile([40, 20, 30, 40, 20, 40], 95))


def test_a_sequence_is_read_frame_by_frame_with_everyone_in_view(tmp_path):
    gt = [(f, i, 10.0 + 20 * i, 20.0, 10.0, 30.0, 1, 1, 1.0) for f in range(1, 5) for i in (1, 2) if f < 4 or i == 1]
    folder = write_sequence(tmp_path / "seq", gt=gt, length=4)
    frames, size = scene_people.people(scene_people.twin(folder), 0)
    assert size == (100, 80) and len(frames) == 4
    assert [sorted(ids.tolist()) for ids, _, _ in frames] == [[1, 2], [1, 2], [1, 2], [1]]
    got = scene_people.measure(frames, size)
    assert got["ended"] == 1 and got["inside"] == 1.0 and got["hidden"] == 0.0

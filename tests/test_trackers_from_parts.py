"""The tracker that docs/trackers_from_parts.md composes from the parts registers, runs end to end, and with every
detection high (no second round) is SORT box for box."""

import re
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

from mtt_sim import trackers
from mtt_sim.lab.experiment import run_episodes

PAGE = Path(__file__).resolve().parent.parent / "docs" / "trackers_from_parts.md"
SHAKE = {"render.camera": "shake", "render.shake": 8}


@pytest.fixture
def bytesort(monkeypatch):
    """The page's tracker, registered in a copy of the registry."""
    monkeypatch.setattr(trackers.base, "REGISTRY", dict(trackers.base.REGISTRY))
    code = re.findall(r"^```python\n(.*?)^```", PAGE.read_text(), re.S | re.M)[0]
    exec(compile(code.split("from mtt_sim.lab.experiment")[0], str(PAGE), "exec"), {"__name__": "page"})
    return trackers.base.REGISTRY["bytesort"]


def outputs(spec: str, steps: int = 80) -> list[tuple[list[int], np.ndarray]]:
    env = gym.make("mtt_sim/Mot17Like-v0", obs_mode="detections", config={"env.max_steps": steps})
    tracker = trackers.make(spec)
    obs, info = env.reset(seed=0)
    tracker.reset(info)
    out = []
    while True:
        tracks = tracker.update(obs)
        out.append((tracks.ids.tolist(), tracks.boxes))
        obs, _, terminated, truncated, _ = env.step(tracks.to_action(env.action_space))
        if terminated or truncated:
            return out


def test_the_page_tracker_without_its_second_round_is_sort_box_for_box(bytesort):
    sort, composed = outputs("sort"), outputs("bytesort:high=-1")
    assert sum(len(ids) for ids, _ in sort) > 100
    for (ids_a, boxes_a), (ids_b, boxes_b) in zip(sort, composed, strict=True):
        assert ids_a == ids_b and np.array_equal(boxes_a, boxes_b)


def test_the_page_tracker_runs_in_the_episode_runner_and_its_camera_motion_compensation_pays(bytesort):
    records = run_episodes("mot17_like", ["sort", "bytesort", "bytesort:cmc=sparse_flow"], seed=0, steps=40,
                           config=SHAKE)
    mota = {r["tracker"]: r["metrics"]["MOTA"] for r in records}
    assert mota["bytesort:cmc=sparse_flow"] > mota["bytesort"] + 0.1 and mota["bytesort:cmc=sparse_flow"] > mota["sort"]

"""mtt-sim: a Gymnasium environment for video multi-target tracking.

Importing the package registers one environment id per shipped scenario, ``mtt_sim/<Name>-v0``. The env itself
(and the simulator behind it) is imported on first use, so the command line answers a mistyped argument at once.
"""

from importlib import metadata

from gymnasium.envs.registration import register, registry

from mtt_sim.core.settings import ConfigError
from mtt_sim.sim.config import Scenario
from mtt_sim.sim.scenario import available, load, shipped_names

__version__ = metadata.version("mtt-sim")


def env_ids() -> dict[str, str]:
    """Shipped scenario keys mapped to their registered env ids."""
    return {key: f"mtt_sim/{name}-v0" for key, name in shipped_names().items()}


for _key, _id in env_ids().items():
    if _id not in registry:
        register(id=_id, entry_point="mtt_sim.env:TrackingEnv", kwargs={"scenario": _key})
if "mtt_sim/Replay-v0" not in registry:  # a recorded sequence: gym.make("mtt_sim/Replay-v0", sequence="path/to/folder")
    register(id="mtt_sim/Replay-v0", entry_point="mtt_sim.env:TrackingEnv", kwargs={"scenario": None})
if "mtt_sim/TrackManagement-v0" not in registry:  # the agent decides which of SORT's candidates to report and keep
    register(id="mtt_sim/TrackManagement-v0", entry_point="mtt_sim.learn.management_env:TrackManagementEnv")


def __getattr__(name: str):
    if name in ("TrackingEnv", "ActionError"):
        from mtt_sim import env

        return getattr(env, name)
    raise AttributeError(f"module 'mtt_sim' has no attribute {name!r}")


__all__ = ["TrackingEnv", "ActionError", "ConfigError", "Scenario", "available", "load", "env_ids"]

"""mtt-sim: a Gymnasium environment for video multi-target tracking.

Importing the package registers one environment id per shipped scenario, ``mtt_sim/<Name>-v0``.
"""

from gymnasium.envs.registration import register, registry

from .env import ActionError, TrackingEnv
from .scenario import ConfigError, Scenario, available, load, load_raw

__version__ = "0.1.0"


def env_ids() -> dict[str, str]:
    """Shipped scenario keys mapped to their registered env ids."""
    return {key: f"mtt_sim/{load_raw(key)[0].get('name', 'Custom')}-v0" for key in available()}


for _key, _id in env_ids().items():
    if _id not in registry:
        register(id=_id, entry_point="mtt_sim.env:TrackingEnv", kwargs={"scenario": _key})

__all__ = ["TrackingEnv", "ActionError", "ConfigError", "Scenario", "available", "load", "env_ids"]

"""shipgym: ship path following under changing dynamics (Gymnasium suite).

``import shipgym`` registers the environments::

    import gymnasium as gym
    import shipgym
    env = gym.make("ShipPathFollow-v0", scenario="rudder_aging", action_mode="rudder")
"""

from gymnasium.envs.registration import register, registry

__version__ = "0.1.0"

#: env id -> default scenario; one id per ship as models land (SPEC §5)
ENV_IDS: dict[str, str] = {"ShipPathFollow-v0": "rudder_aging"}

for _env_id, _scenario in ENV_IDS.items():
    if _env_id not in registry:
        register(
            id=_env_id,
            entry_point="shipgym.envs.path_follow:ShipPathFollowEnv",
            vector_entry_point="shipgym.envs.vector:ShipPathFollowVectorEnv",
            kwargs={"scenario": _scenario},
        )

__all__ = ["ENV_IDS", "__version__"]

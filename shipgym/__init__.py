"""shipgym: ship path following under changing dynamics (Gymnasium suite).

``import shipgym`` registers the environments::

    import gymnasium as gym
    import shipgym
    env = gym.make("ShipPathFollow-v0", scenario="rudder_aging", action_mode="rudder")
"""

from gymnasium.envs.registration import register, registry

__version__ = "0.1.0"

#: env id -> default scenario: one id per ship, same contract and keyword arguments.
#: The per-ship ``-v1`` ids default to that ship's rudder aging (a changing plant);
#: their ``-v0`` ids keep the scenarios they always had (Gymnasium's versioning rule: a
#: different default is a different env).
ENV_IDS: dict[str, str] = {
    "ShipPathFollow-v0": "rudder_aging",
    "ShipPathFollow-EssoOsaka-v0": "osaka_stochastic_current",
    "ShipPathFollow-Mariner-v0": "mariner_track",
    "ShipPathFollow-Blanke-v0": "blanke_current_shift",
    "ShipPathFollow-EssoOsaka-v1": "esso_osaka_rudder_aging",
    "ShipPathFollow-Mariner-v1": "mariner_rudder_aging",
    "ShipPathFollow-Blanke-v1": "blanke_rudder_aging",
    "ShipPathFollow-KVLCC2-v1": "kvlcc2_rudder_aging",
}

for _env_id, _scenario in ENV_IDS.items():
    if _env_id not in registry:
        register(
            id=_env_id,
            entry_point="shipgym.envs.path_follow:ShipPathFollowEnv",
            vector_entry_point="shipgym.envs.vector:ShipPathFollowVectorEnv",
            kwargs={"scenario": _scenario},
        )

#: training env: a new scenario from a distribution (configs/distributions) at every reset
RANDOMIZED_ENV_ID = "ShipPathFollowRandomized-v0"
if RANDOMIZED_ENV_ID not in registry:
    register(
        id=RANDOMIZED_ENV_ID,
        entry_point="shipgym.envs.randomized:ShipPathFollowRandomizedEnv",
        kwargs={"distribution": "train"},
    )

__all__ = ["ENV_IDS", "RANDOMIZED_ENV_ID", "__version__"]

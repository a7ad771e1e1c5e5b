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

#: env id -> ``max_episode_steps`` of its spec: its default scenario's episode, ceil(time_limit
#: / Ts) control periods; the randomised env's: the longest episode its ``train``
#: distribution can draw (ScenarioDistribution.max_episode_steps).  Written out so that
#: ``import shipgym`` loads no scenario; tests/shipgym/envs/test_seeding.py derives each.
#: The env truncates itself at its scenario's time limit: with a longer scenario than the
#: id's, pass ``gym.make(..., max_episode_steps=-1)`` (no TimeLimit) or its own steps.
MAX_EPISODE_STEPS: dict[str, int] = {
    "ShipPathFollow-v0": 180,
    "ShipPathFollow-EssoOsaka-v0": 4000,
    "ShipPathFollow-Mariner-v0": 2400,
    "ShipPathFollow-Blanke-v0": 3500,
    "ShipPathFollow-EssoOsaka-v1": 632,
    "ShipPathFollow-Mariner-v1": 894,
    "ShipPathFollow-Blanke-v1": 1290,
    "ShipPathFollow-KVLCC2-v1": 476,
    "ShipPathFollowRandomized-v0": 5104,
}

for _env_id, _scenario in ENV_IDS.items():
    if _env_id not in registry:
        register(
            id=_env_id,
            entry_point="shipgym.envs.path_follow:ShipPathFollowEnv",
            vector_entry_point="shipgym.envs.vector:ShipPathFollowVectorEnv",
            max_episode_steps=MAX_EPISODE_STEPS[_env_id],
            # every reset(seed=…) draws a trial (the default suite's ranges) from the env's
            # generator; randomize=False: the scenario itself, as the class defaults to
            kwargs={"scenario": _scenario, "randomize": True},
        )

#: training env: a new scenario from a distribution (configs/distributions) at every reset
RANDOMIZED_ENV_ID = "ShipPathFollowRandomized-v0"
if RANDOMIZED_ENV_ID not in registry:
    register(
        id=RANDOMIZED_ENV_ID,
        entry_point="shipgym.envs.randomized:ShipPathFollowRandomizedEnv",
        max_episode_steps=MAX_EPISODE_STEPS[RANDOMIZED_ENV_ID],
        kwargs={"distribution": "train"},
    )

__all__ = ["ENV_IDS", "MAX_EPISODE_STEPS", "RANDOMIZED_ENV_ID", "__version__"]

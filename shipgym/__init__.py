"""shipgym: ship path following under changing dynamics (Gymnasium suite).

``import shipgym`` registers the environments::

    import gymnasium as gym
    import shipgym
    env = gym.make("ShipPathFollow-v0", scenario="rudder_aging", action_mode="rudder")
"""

from collections import ChainMap

from gymnasium.envs.registration import register, registry

from shipgym.models.ship import SHIPS, Ship, ShipTable

__version__ = "0.1.0"

#: env id -> default scenario: each ship record's ``env_ids``, same contract and keyword
#: arguments.  The per-ship ``-v1`` ids default to that ship's rudder aging (a changing
#: plant); their ``-v0`` ids keep the scenarios they always had (Gymnasium's versioning rule:
#: a different default is a different env).
ENV_IDS: ShipTable[str] = ShipTable(lambda ship: ((e.id, e.scenario) for e in ship.env_ids))

#: training env: a new scenario from a distribution (configs/distributions) at every reset
RANDOMIZED_ENV_ID = "ShipPathFollowRandomized-v0"

#: env id -> ``max_episode_steps`` of its spec: its default scenario's episode, ceil(time_limit
#: / Ts) control periods (each ship record's ``env_ids``); the randomised env's: the longest
#: episode its ``train`` distribution can draw (ScenarioDistribution.max_episode_steps).
#: Written out so that ``import shipgym`` loads no scenario; tests/shipgym/envs/test_seeding.py
#: derives each.  The env truncates itself at its scenario's time limit: with a longer
#: scenario than the id's, pass ``gym.make(..., max_episode_steps=-1)`` (no TimeLimit) or its
#: own steps.
MAX_EPISODE_STEPS: ChainMap[str, int] = ChainMap(
    ShipTable(lambda ship: ((e.id, e.max_episode_steps) for e in ship.env_ids)),
    {RANDOMIZED_ENV_ID: 5104},
)


def register_envs(ship: Ship) -> None:
    """Register every gymnasium id of ``ship``'s record that is not registered yet."""
    for env in ship.env_ids:
        if env.id not in registry:
            register(
                id=env.id,
                entry_point="shipgym.envs.path_follow:ShipPathFollowEnv",
                vector_entry_point="shipgym.envs.vector:ShipPathFollowVectorEnv",
                max_episode_steps=env.max_episode_steps,
                # every reset(seed=…) draws a trial (the default suite's ranges) from the
                # env's generator; randomize=False: the scenario itself, as the class
                # defaults to
                kwargs={"scenario": env.scenario, "randomize": True},
            )


for _ship in SHIPS.values():
    register_envs(_ship)

if RANDOMIZED_ENV_ID not in registry:
    register(
        id=RANDOMIZED_ENV_ID,
        entry_point="shipgym.envs.randomized:ShipPathFollowRandomizedEnv",
        max_episode_steps=MAX_EPISODE_STEPS[RANDOMIZED_ENV_ID],
        kwargs={"distribution": "train"},
    )

__all__ = ["ENV_IDS", "MAX_EPISODE_STEPS", "RANDOMIZED_ENV_ID", "__version__", "register_envs"]

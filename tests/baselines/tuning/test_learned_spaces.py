"""Every learned tuning config's search space builds a valid agent config at its corners."""

from __future__ import annotations

import pytest

from shipgym_baselines.training.agents import load_agent_config
from shipgym_baselines.tuning.learned import apply_overrides
from shipgym_baselines.tuning.space import list_tuning, load_tuning

LEARNED = [n for n in list_tuning() if load_tuning(n).kind == "learned"]


def test_every_learned_agent_has_a_study() -> None:
    """PPO, PPO-guidance, SAC, TD3 and the adaptive agent are all tuned."""
    assert {"ppo", "ppo_guidance", "recurrent_ppo", "sac", "td3"} <= set(LEARNED)


@pytest.mark.parametrize("name", LEARNED)
def test_each_corner_of_the_space_is_a_valid_agent_config(name: str) -> None:
    """The fixed settings with each choice of each categorical parameter and each end of
    each range (one parameter varied at a time from the first corner, then the last corner):
    accepted by the agent config's own validation (e.g. a per-ship discount needs the
    batched envs), and the values reach the config."""
    config = load_tuning(name)
    agent = load_agent_config(config.training.agent)
    options = {
        key: spec.choices if spec.choices is not None else [spec.low, spec.high]
        for key, spec in config.params.items()
    }
    first = {key: values[0] for key, values in options.items()}
    points = [{**first, key: value} for key, values in options.items() for value in values]
    points.append({key: values[-1] for key, values in options.items()})
    for point in points:
        overrides = {**config.fixed, **point}
        built = apply_overrides(agent, overrides)
        for key, value in overrides.items():
            block, _, field = key.partition(".")
            got = getattr(built, block)
            got = got[field] if isinstance(got, dict) else getattr(got, field)
            if field == "net_arch" and isinstance(value, str):
                value = [int(w) for w in value.split("x")]
            assert got == value, (name, key)

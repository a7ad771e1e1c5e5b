"""--settings tuned: the chosen settings and the final block over an agent config, the
refusal without chosen settings, and the final block's validation (docs/tuning.md)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
import yaml
from pydantic import ValidationError

from shipgym_baselines.errors import RunError
from shipgym_baselines.training.agents import load_agent_config
from shipgym_baselines.tuning.chosen import write_chosen
from shipgym_baselines.tuning.space import FinalSpec, TuningConfig, load_tuning
from shipgym_baselines.tuning.tuned import tuned_agent

CHOSEN = {
    "hyperparams.learning_rate": 7.0e-4,
    "hyperparams.gamma": 0.97,
    "policy_kwargs.net_arch": "128x128",
    "env.context_features": True,
}
STUDY = {"study": "ppo", "report": "configs/tuning/reports/ppo/tuning_report.json"}


def test_the_packaged_ppo_study_has_the_protocols_final_block() -> None:
    final = load_tuning("ppo").final
    assert final is not None
    assert final.n_timesteps == 3_000_000 and final.seeds == [0, 1, 2]
    assert final.select_on == "relative_cost"
    assert (final.plateau.min_gain, final.plateau.window) == (0.02, 0.25)
    assert final.plateau.metric == "selection"


@pytest.mark.parametrize(
    ("final", "match"),
    [
        ({"n_timesteps": 0}, "n_timesteps"),
        ({"n_timesteps": 1000, "seeds": []}, "seeds"),
        ({"n_timesteps": 1000, "seeds": [0, 0]}, "distinct"),
        ({"n_timesteps": 1000, "seeds": [-1]}, "non-negative"),
        ({"n_timesteps": 1000, "select_on": "return"}, "select_on: relative_cost"),
        ({"n_timesteps": 1000, "select_on": "best"}, "select_on"),
        ({"n_timesteps": 1000, "plateau": {"window": 1.5}}, "window"),
        ({"n_timesteps": 1000, "budget": 3}, "budget"),
    ],
)
def test_a_bad_final_block_names_its_key(final: dict[str, Any], match: str) -> None:
    with pytest.raises(ValidationError, match=match):
        FinalSpec.model_validate(final)


def test_a_classical_study_has_no_final_block() -> None:
    data = load_tuning("pid_los").model_dump()
    data["final"] = {"n_timesteps": 1000}
    with pytest.raises(ValidationError, match="final"):
        TuningConfig.model_validate(data)


def test_chosen_settings_and_the_final_block_reach_the_agent_config(tmp_path: Path) -> None:
    file, _ = write_chosen("ppo", "all", CHOSEN, STUDY, folder=tmp_path)
    agent, tuned_from = tuned_agent(load_agent_config("ppo"), tmp_path)
    assert agent.hyperparams["learning_rate"] == 7.0e-4 and agent.hyperparams["gamma"] == 0.97
    assert agent.hyperparams["n_steps"] == 256  # the config's, not tuned, kept
    assert agent.policy_kwargs["net_arch"] == [128, 128]
    assert agent.env.context_features is True
    assert agent.n_timesteps == 3_000_000 and agent.eval.select_on == "relative_cost"
    assert agent.plateau is not None and agent.plateau.metric == "selection"
    assert tuned_from["chosen"] == str(file) and tuned_from["settings"] == CHOSEN
    assert tuned_from["report"] == STUDY["report"] and tuned_from["final"]["seeds"] == [0, 1, 2]
    # the packaged file is recorded by its repository path, not this machine's
    _, packaged = tuned_agent(load_agent_config("ppo"))
    assert packaged["chosen"] == "configs/tuning/chosen/ppo.yaml"


@pytest.mark.parametrize(
    ("document", "match"), [(None, "has no 'all' section"), ({}, "has an empty 'all' section")]
)
def test_no_chosen_settings_is_refused_naming_the_file(
    document: dict[str, Any] | None, match: str, tmp_path: Path
) -> None:
    if document is not None:
        (tmp_path / "ppo.yaml").write_text(yaml.safe_dump({"ships": {"all": document}}))
    with pytest.raises(RunError, match=match) as found:
        tuned_agent(load_agent_config("ppo"), tmp_path)
    assert str(tmp_path / "ppo.yaml") in str(found.value)


def test_an_agent_without_a_tuning_config_is_refused() -> None:
    with pytest.raises(RunError, match="tuning config of agent 'td3_custom'"):
        tuned_agent(load_agent_config("td3").model_copy(update={"name": "td3_custom"}))

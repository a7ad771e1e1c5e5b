"""Every controller has one look, the same in every figure and process."""

from __future__ import annotations

from shipgym_baselines.plots.style import controller_style
from shipgym_baselines.registry import CONTROLLERS


def test_built_in_controllers_have_distinct_fixed_styles() -> None:
    names = [*CONTROLLERS, "ppo", "ppo_guidance", "recurrent_ppo", "sac", "td3"]
    names += ["ppo_history", "dagger", "bc"]
    looks = {(controller_style(n).color, controller_style(n).linestyle) for n in names}
    assert len(looks) == len(set(names))


def test_unknown_names_get_a_stable_style() -> None:
    a = controller_style("my_module:MyPolicy")
    assert a == controller_style("my_module:MyPolicy")  # pure function of the name
    assert a.color.startswith("#") and a.linestyle in ("-", "--", "-.", ":")

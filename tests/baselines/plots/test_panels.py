"""What the figures share: the panel columns by controller family."""

from __future__ import annotations

from shipgym_baselines.plots.panels import (
    PANEL_CONTROLLERS,
    controller_family,
    family_panels,
)
from shipgym_baselines.plots.style import controller_style
from shipgym_baselines.policy import Style
from shipgym_baselines.registry import register_controller


def test_a_big_family_is_split_over_panels() -> None:
    names = [f"pid_{i}" for i in range(7)] + ["lqr", "zero_rudder", "my_plugin"]
    panels = family_panels(names, {"my_plugin": "learned"})
    assert [title for title, _ in panels] == [
        "PID (1/2)",
        "PID (2/2)",
        "LQR",
        "learned",
        "references",
    ]
    assert all(len(members) <= PANEL_CONTROLLERS for _, members in panels)
    assert sorted(n for _, members in panels for n in members) == sorted(names)


def test_the_figures_draw_a_controller_as_registered(scratch_registry: None) -> None:
    """Family and look come from the registration (its name says nothing); a name nothing
    declares them for takes its kind's family and its name's hashed look."""
    from shipgym_baselines.classical.reference import ZeroRudder

    look = Style("#123456", "--", "o")
    register_controller("test_mine", lambda: ZeroRudder(), family="NMPC", look=look)
    assert (controller_family("test_mine"), controller_style("test_mine")) == ("NMPC", look)
    assert controller_family("ppo") == "learned" and controller_family("oracle") == "references"
    assert controller_family("my_ref", "reference") == "references"
    assert controller_family("my_agent", "learned") == "learned"
    assert controller_family("my_plugin", "classical") == "other"

"""The no-change twin of a scenario: the same trial with its change removed."""

from __future__ import annotations

from shipgym.scenarios.loader import load_scenario
from shipgym.scenarios.trials import TrialRandomization, trial_scenario
from shipgym.scenarios.twins import has_change, nominal_twin, same_trial

RANDOMIZE = TrialRandomization(
    cross_track_offset_L=(-1.0, 1.0),
    heading_error_deg=(-10.0, 10.0),
    jump_time_jitter_s=(-5.0, 5.0),
    current_speed_factor=(0.8, 1.2),
    current_direction_deg=(-20.0, 20.0),
)


def test_a_parameter_change_removed_gives_the_nominal_scenario_on_the_same_route() -> None:
    """esso_osaka_rudder_aging's twin is esso_osaka_nominal, setting for setting (the
    nominal file says it is the twin: same route, start and timing)."""
    aging = load_scenario("esso_osaka_rudder_aging")
    twin = nominal_twin(aging)
    assert has_change(aging) and twin is not None and not twin.config.events
    assert twin.name == aging.name
    assert same_trial(twin, load_scenario("esso_osaka_nominal"))
    assert not same_trial(aging, load_scenario("esso_osaka_nominal"))


def test_a_current_appearing_is_removed_with_its_calm_first_phase() -> None:
    """A two-phase current whose first phase is calm and steady: the twin has no current
    (the default), and keeps the scenario's own time limit."""
    shift = load_scenario("esso_osaka_current_shift")
    twin = nominal_twin(shift, name="twin:esso_osaka_current_shift")
    assert twin is not None and twin.name == "twin:esso_osaka_current_shift"
    assert twin.config.disturbances.current.kind == "constant"
    assert twin.config.disturbances.current.speed == 0.0
    assert twin.config.time_limit == shift.config.time_limit
    nominal = load_scenario("esso_osaka_nominal")
    assert twin.config.path == nominal.config.path
    assert twin.config.initial_state == nominal.config.initial_state


def test_a_two_phase_current_keeps_its_first_phase_for_the_whole_episode() -> None:
    base = load_scenario("esso_osaka_current_shift")
    current = {"speed": 0.1, "second_speed": 0.2, "sigma": 0.003, "mu": 0.05}
    scenario = base.with_overrides({"disturbances": {"current": current}})
    twin = nominal_twin(scenario)
    assert twin is not None
    kept = twin.config.disturbances.current
    assert kept.kind == "gauss_markov"
    assert (kept.speed, kept.sigma, kept.mu) == (0.1, 0.003, 0.05)
    assert kept.direction_deg == scenario.config.disturbances.current.direction_deg


def test_a_scenario_without_a_change_has_no_twin() -> None:
    nominal = load_scenario("esso_osaka_nominal")
    assert not has_change(nominal) and nominal_twin(nominal) is None


def test_the_twin_of_a_trial_is_the_trial_of_the_twin() -> None:
    """Every range is drawn from the seed alone, so drawing a trial and removing the change
    commute, seed for seed, on a parameter change and on a current shift."""
    for name in ("rudder_aging", "esso_osaka_current_shift", "mariner_maneuverability_change"):
        scenario = load_scenario(name)
        for seed in (10_000, 10_001, 10_007):
            a = nominal_twin(trial_scenario(scenario, RANDOMIZE, seed))
            b = trial_scenario(nominal_twin(scenario), RANDOMIZE, seed)
            assert a is not None and b is not None and same_trial(a, b), (name, seed)

"""Trial randomisation: what an evaluation seed draws (docs/leaderboard.md)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgym.paths import segment_frame
from shipgym.scenarios.loader import load_scenario
from shipgym.scenarios.trials import (
    TRIAL_STREAM,
    TrialRandomization,
    apply_trial,
    draw_trial,
    trial_draws,
    trial_scenario,
)

FULL = TrialRandomization(
    cross_track_offset_L=(-0.5, 0.5),
    heading_error_deg=(-10.0, 10.0),
    jump_time_jitter_s=(-3.0, 3.0),
    current_speed_factor=(0.8, 1.2),
    current_direction_deg=(-20.0, 20.0),
)


def test_draws_are_reproducible_per_seed_and_differ_across_seeds() -> None:
    assert trial_draws(FULL, 7) == trial_draws(FULL, 7)
    seen = {tuple(trial_draws(FULL, s).values()) for s in range(20)}
    assert len(seen) == 20
    for s in range(50):
        d = trial_draws(FULL, s)
        for name, value in d.items():
            lo, hi = getattr(FULL, name)
            assert lo <= value <= hi


def test_a_range_left_out_does_not_change_the_others() -> None:
    fewer = TrialRandomization(heading_error_deg=(-10.0, 10.0))
    assert trial_draws(fewer, 3)["heading_error_deg"] == trial_draws(FULL, 3)["heading_error_deg"]


def test_the_trial_moves_the_start_across_the_first_leg_and_shifts_the_jump() -> None:
    base = load_scenario("rudder_aging")
    seed = 11
    d = trial_draws(FULL, seed)
    trial = trial_scenario(base, FULL, seed)
    assert trial.name == base.name
    wp = base.config.path.waypoints
    e0 = segment_frame(base.config.initial_state.x, base.config.initial_state.y, wp[0], wp[1])
    s = trial.config.initial_state
    e1 = segment_frame(s.x, s.y, wp[0], wp[1])
    assert e1.cross_track - e0.cross_track == pytest.approx(
        d["cross_track_offset_L"] * base.ship_length
    )
    assert e1.along_track == pytest.approx(e0.along_track)
    assert s.heading_deg == pytest.approx(
        base.config.initial_state.heading_deg + d["heading_error_deg"]
    )
    assert trial.config.events[0].time == pytest.approx(12.0 + d["jump_time_jitter_s"])
    assert trial.schedule.first_change_time == pytest.approx(12.0 + d["jump_time_jitter_s"])


def test_the_trial_scales_and_turns_the_current() -> None:
    base = load_scenario("osaka_curved")  # a constant current
    c0 = base.config.disturbances.current
    d = trial_draws(FULL, 5)
    c = trial_scenario(base, FULL, 5).config.disturbances.current
    assert c.speed == pytest.approx(c0.speed * d["current_speed_factor"])
    assert c.direction_deg == pytest.approx(c0.direction_deg + d["current_direction_deg"])


def test_a_current_shift_is_scaled_and_its_switch_jittered() -> None:
    base = load_scenario("blanke_current_shift")  # two-phase: calm, then 0.5 m/s at 150 s
    c0 = base.config.disturbances.current
    d = trial_draws(FULL, 2)
    c = trial_scenario(base, FULL, 2).config.disturbances.current
    assert c.second_speed == pytest.approx(c0.second_speed * d["current_speed_factor"])
    switch0 = 0.5 * base.config.time_limit if c0.switch_time is None else c0.switch_time
    assert c.switch_time == pytest.approx(switch0 + d["jump_time_jitter_s"])


def test_no_randomisation_is_the_scenario_itself() -> None:
    base = load_scenario("nominal")
    assert trial_scenario(base, None, 3) is base
    assert trial_scenario(base, TrialRandomization(), 3) is base


def test_jitter_keeps_events_inside_the_episode() -> None:
    base = load_scenario("rudder_aging")
    late = TrialRandomization(jump_time_jitter_s=(500.0, 600.0))
    t = trial_scenario(base, late, 0).config.events[0].time
    assert t == pytest.approx(base.config.time_limit - base.control_period)
    assert not math.isnan(t)


def test_bad_ranges_are_refused() -> None:
    with pytest.raises(ValueError, match="low ≤ high"):
        TrialRandomization(heading_error_deg=(5.0, -5.0))


def test_an_evaluation_seed_is_a_draw_from_its_stream_then_its_application() -> None:
    """trial_scenario = apply_trial(draw_trial(the seed's own stream)): the two pure parts
    the envs reuse with their own generator."""
    base = load_scenario("blanke_current_shift")
    for seed in (0, 5):
        draws = draw_trial(FULL, np.random.default_rng([TRIAL_STREAM, seed]))
        assert draws == trial_draws(FULL, seed)
        assert apply_trial(base, draws).config == trial_scenario(base, FULL, seed).config
    assert apply_trial(base, {}) is base
    rng = np.random.default_rng(3)
    first, second = draw_trial(FULL, rng), draw_trial(FULL, rng)
    assert first != second  # a generator's stream goes on

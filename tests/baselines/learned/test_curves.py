"""Learning curves, the plateau rule and the relative-cost selection metric (issue 21)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from shipgym_baselines.errors import RunError
from shipgym_baselines.learned.curves import CURVE_FILE, PlateauRule, load_curve, write_curve
from shipgym_baselines.learned.selection import geometric_mean_ratio, validation_trials


def test_curve_round_trip_and_monotone_steps(tmp_path) -> None:
    returns = [[-10.0, -30.0], [-8.0, -12.0], [-5.0, -5.0]]
    write_curve(tmp_path, [1000, 2000, 3000], returns, selection=[2.0, 1.5, 1.2])
    curve = load_curve(tmp_path)
    assert curve["env_steps"] == [1000, 2000, 3000]
    assert curve["mean_return"] == [-20.0, -10.0, -5.0]
    assert curve["std_return"] == [10.0, 2.0, 0.0]
    assert curve["selection"] == [2.0, 1.5, 1.2]
    assert np.all(np.diff(curve["env_steps"]) > 0)
    assert load_curve(tmp_path / "elsewhere") is None


@pytest.mark.parametrize(
    "curve, match",
    [
        ({"env_steps": [2, 1], "mean_return": [0, 0], "std_return": [0, 0]}, "increasing"),
        ({"env_steps": [1, 2], "mean_return": [0], "std_return": [0, 0]}, "different lengths"),
        ({"env_steps": [1], "mean_return": [math.nan], "std_return": [0]}, "non-finite"),
        ({"env_steps": [1], "mean_return": [0]}, "keys"),
    ],
)
def test_bad_curves_are_named(tmp_path, curve, match) -> None:
    (tmp_path / CURVE_FILE).write_text(json.dumps(curve))
    with pytest.raises(RunError, match=match):
        load_curve(tmp_path)


def test_plateau_rule_on_synthetic_curves() -> None:
    rule = PlateauRule(min_gain=0.02, window=0.25, min_evaluations=4)
    steps = list(range(10_000, 110_000, 10_000))  # 10 evaluations up to 100 k
    # still improving: -1000/(1 + s/10k); the best before the last quarter (≤ 75 k) is at
    # 70 k (-1000/8), the best now at 100 k (-1000/11): a gain of 3/11 ≈ 27 %
    improving = [-1000.0 / (1 + s / 10_000) for s in steps]
    assert rule.gain(steps, improving) == pytest.approx(3 / 11)
    assert not rule.plateaued(steps, improving)
    # flat after 50 k: best over the last 25 % (after 75 k) equals the best before
    flat = [-100.0 + 50.0 * max(0.0, 1 - s / 50_000) for s in steps]
    assert rule.gain(steps, flat) == 0.0
    assert rule.plateaued(steps, flat)
    # a 1 % gain is a plateau at 2 %, not at 0.5 %
    slow = [-100.0] * 8 + [-99.0, -99.0]
    assert rule.plateaued(steps, slow)
    assert not PlateauRule(min_gain=0.005).plateaued(steps, slow)
    # too few evaluations: no verdict
    assert rule.gain(steps[:3], flat[:3]) is None
    # the selection metric: lower is better
    by_cost = PlateauRule(metric="selection")
    assert not by_cost.plateaued(steps, [3.0 - s / 50_000 for s in steps])
    assert by_cost.plateaued(steps, [1.0] * 10)


def test_geometric_mean_ratio_counts_every_trial_equally() -> None:
    # a ship with costs 1000x another's: the ratio, not the size, decides
    assert geometric_mean_ratio([2.0, 2000.0], [1.0, 1000.0]) == pytest.approx(2.0)
    assert geometric_mean_ratio([4.0, 1000.0], [1.0, 1000.0]) == pytest.approx(2.0)
    with pytest.raises(ValueError):
        geometric_mean_ratio([1.0], [1.0, 2.0])


def test_validation_trials_are_fixed_and_never_heldout() -> None:
    trials = validation_trials("validation", 4)
    assert trials == [(f"validation:{i}", 10_000 + i) for i in range(4)]
    with pytest.raises(RunError, match="not a test split"):
        validation_trials("train", 4)
    with pytest.raises(RunError, match="scenarios"):
        validation_trials("validation", 10_000)


def test_shipped_curves_are_found_and_drawn_on_the_page(tmp_path) -> None:
    from shipgym_baselines.figures import LEARNING_CURVES_STEM, plot_learning_curves
    from shipgym_baselines.learned.curves import agent_curves
    from shipgym_baselines.pages import figure_sections

    root = tmp_path / "policies"
    for seed in (1, 0):
        folder = root / "ppo" / f"seed_{seed}"
        folder.mkdir(parents=True)
        write_curve(folder, [100, 200], [[-3.0, -1.0], [-2.0, -1.0 - seed]])
    curves = agent_curves("ppo", root)
    assert [c["seed"] for c in curves] == [0, 1]
    assert agent_curves("sac", root) == []
    figures = tmp_path / "figures"
    files = plot_learning_curves(figures, {"ppo": curves, "sac": []}, vector=True)
    assert {f.name for f in files} == {f"{LEARNING_CURVES_STEM}.png", f"{LEARNING_CURVES_STEM}.svg"}
    assert plot_learning_curves(figures, {"sac": []}) == []
    ranking_html, scenario_html, legend_names = figure_sections(files)
    assert "learning curves" in ranking_html and scenario_html == "" and legend_names == []

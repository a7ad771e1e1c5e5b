"""Learning curves, the plateau rule and the relative-cost selection metric (docs/training.md)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from shipgym_baselines.errors import RunError
from shipgym_baselines.learned.curves import CURVE_FILE, PlateauRule, load_curve, write_curve
from shipgym_baselines.training.selection import geometric_mean_ratio, validation_trials


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
    # not before min_fraction of the budget: flat at 100 k of a 300 k budget goes on
    floor = PlateauRule(metric="selection", min_fraction=0.34)
    assert not floor.plateaued(steps, [1.0] * 10, budget=300_000)
    assert floor.plateaued(steps, [1.0] * 10, budget=290_000)


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
    from shipgym_baselines.learned.curves import agent_curves
    from shipgym_baselines.page.figures import figure_sections
    from shipgym_baselines.plots.curves import (
        LEARNING_CURVES_STEM,
        plot_learning_curves,
    )

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


def test_selection_runs_on_all_32_validation_trials_by_default() -> None:
    """Model selection and stopping (eval.n_episodes), the learned studies' objective and
    the shipped agent configs: every validation trial, validation:0 … validation:31."""
    from shipgym_baselines.training.agents import EvalConfig, list_agent_configs, load_agent_config
    from shipgym_baselines.training.selection import SELECTION_TRIALS
    from shipgym_baselines.tuning.space import list_tuning, load_tuning
    from shipgym_baselines.tuning.validation import validation_trials as study_trials

    every = [(f"validation:{i}", 10_000 + i) for i in range(32)]
    assert SELECTION_TRIALS == 32 and EvalConfig().n_episodes == 32
    assert validation_trials("validation") == every
    for name in list_agent_configs():
        agent = load_agent_config(name)
        assert agent.eval.distribution == "validation", name
        assert validation_trials(agent.eval.distribution, agent.eval.n_episodes) == every, name
    learned = [load_tuning(n) for n in list_tuning() if load_tuning(n).kind == "learned"]
    assert learned
    for config in learned:
        v = config.validation
        trials = study_trials(v.distribution, None, v.per_ship, config.ships)
        assert [(t.name, t.seed) for t in trials] == every, config.name


def test_selection_never_names_the_leaderboards_test_splits() -> None:
    """The held-out and in-range splits (test_only) are refused by the selection's trials and
    by an agent config's eval block."""
    from pydantic import ValidationError

    from shipgym_baselines.training.agents import EvalConfig

    for split in ("heldout", "inrange"):
        with pytest.raises(RunError, match="test_only"):
            validation_trials(split, 4)
        with pytest.raises(ValidationError, match="test_only"):
            EvalConfig(distribution=split)


def test_the_run_folders_references_are_read_again_for_another_oracle_revision(
    tmp_path,
) -> None:
    """``eval/reference_costs.json`` records the oracle revision it was read at; a file of
    another revision (or the same trials without one) is replaced by the current oracle's
    costs (the shipped table holds every validation trial)."""
    from shipgym_baselines.references import oracle_header
    from shipgym_baselines.training.selection import REFERENCE_FILE, reference_costs

    trials = [("validation:0", 10_000), ("validation:1", 10_001)]
    stale = {"oracle": {"revision": -1}, "env_revision": oracle_header()["env_revision"]}
    fake = [{"cost": 123.0, "reference": "oracle"}] * 2
    wanted = [list(t) for t in trials]
    (tmp_path / REFERENCE_FILE).write_text(
        json.dumps({"trials": wanted, "references": fake, **stale})
    )
    refs = reference_costs(trials, tmp_path)
    assert [r["reference"] for r in refs] == ["oracle", "oracle"]
    assert all(r["cost"] != 123.0 for r in refs)
    data = json.loads((tmp_path / REFERENCE_FILE).read_text())
    assert data["oracle"] == oracle_header()["oracle"] and data["references"] == refs
    assert reference_costs(trials, tmp_path) == refs  # read back, the same revision


def test_curves_with_a_selection_metric_are_drawn_as_the_gap_to_the_oracle(
    tmp_path, monkeypatch
) -> None:
    """A run that selects on the validation cost ratio is drawn on it (log axis, the oracle
    at 1, each seed's best point ringed); one without it on its return."""
    from shipgym_baselines.plots import curves as curve_figures

    drawn = {}

    def keep(fig, out_dir, stem, **_):
        drawn[stem] = fig
        return []

    monkeypatch.setattr(curve_figures, "save_figure", keep)
    ratio = {"env_steps": [10, 20, 30], "mean_return": [-3.0, -2.0, -2.5], "std_return": [1.0] * 3}
    curves = {
        "dagger": [{**ratio, "selection": [5.0, 2.0, 2.5], "seed": 0}],
        "ppo": [{**ratio, "seed": 0}],
    }
    curve_figures.plot_learning_curves(tmp_path, curves, stem="mine")
    by_cost, by_return = drawn["mine"].axes[:2]
    assert by_cost.get_yscale() == "log" and by_return.get_yscale() == "linear"
    assert by_cost.get_ylabel() == "validation cost / oracle's"
    lines = {line.get_label(): line for line in by_cost.get_lines()}
    assert list(lines["oracle = 1"].get_ydata()) == [1.0, 1.0]
    rings = [ln for ln in by_cost.get_lines() if ln.get_marker() == "o"]
    assert [(float(r.get_xdata()[0]), float(r.get_ydata()[0])) for r in rings] == [(20.0, 2.0)]


def _curve(selection: list[float], seed: int = 0) -> dict:
    steps = [100 * (i + 1) for i in range(len(selection))]
    return {"env_steps": steps, "selection": selection, "seed": seed}


@pytest.mark.parametrize(
    ("selection", "flag"),
    [
        ([33.63, 33.62, 33.62], "never improved"),  # best 0.03 % under the first
        ([5.91, 6.5, 44.27], "unstable"),  # the first is the best, the last 7.5× it
        ([17.5, 7.39, 19.36], "unstable"),  # ends at 2.6× its best
        ([29.4, 1.27, 1.67], None),  # ends at 1.3× its best
        ([10.0, 8.5, 8.5], None),  # 15 % under the first: improved
        ([10.0, 9.5, 9.5], "never improved"),  # 5 % under the first
        ([4.0], None),  # one evaluation: not judged
    ],
)
def test_the_seed_flag_rule(selection: list[float], flag: str | None) -> None:
    from shipgym_baselines.learned.curves import seed_flag

    found = seed_flag(_curve(selection))
    assert (found or {}).get("flag") == flag
    if found is not None and len(selection) > 1:
        assert (found["first"], found["best"], found["final"]) == (
            selection[0],
            min(selection),
            selection[-1],
        )


def test_the_shipped_agents_flagged_seeds() -> None:
    """The shipped curves flag recurrent_ppo's seeds 0 (unstable) and 1 (flat at 33.6× the
    oracle), sac's three seeds and td3's seed 2; ppo's and dagger's none."""
    from shipgym_baselines.learned.curves import agent_curves, seed_flags

    flagged = {name: [f["training_seed"] for f in seed_flags(agent_curves(name))] for name in (
        "recurrent_ppo", "sac", "td3", "ppo", "dagger")}  # fmt: skip
    assert flagged["recurrent_ppo"] == [0, 1]
    assert flagged["sac"] == [0, 1, 2]
    assert flagged["td3"] == [2]
    assert flagged["ppo"] == flagged["dagger"] == []


def test_flagged_seeds_are_marked_in_the_ranking_with_the_rule() -> None:
    from shipgym_baselines.leaderboard.outputs import add_seed_flags
    from shipgym_baselines.page.sections import flag_lines, ranking_tables

    head = {"split": "catalogue", "runs": 4}
    rows = [
        {**head, "controller": "agent", "kind": "learned", "cost_ratio_iqm": 2.0},
        {**head, "controller": "pid_los", "kind": "classical", "cost_ratio_iqm": 3.0},
    ]
    for row in rows:
        row["cost_ratio_iqm_ci95"] = [row["cost_ratio_iqm"] - 0.1, row["cost_ratio_iqm"] + 0.1]
    add_seed_flags(rows, {"agent": [_curve([4.0, 4.0], seed=1), _curve([4.0, 1.0], seed=2)]})
    assert rows[0]["seed_flags"] == [
        {"training_seed": 1, "flag": "never improved", "first": 4.0, "best": 4.0, "final": 4.0}
    ]
    assert "seed_flags" not in rows[1]
    (line,) = flag_lines(rows)
    assert "agent: seed 1 never improved (first 4.00, best 4.00, last 4.00)" in line
    assert "never improved' when" in line
    html = ranking_tables(rows)
    assert 'class="flag"' in html and "⚑1" in html

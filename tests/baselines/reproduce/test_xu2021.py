"""``shipgym reproduce xu2021``: Xu, Oliveira & Guedes Soares (2021) §5.2 on the Esso Osaka."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from shipgym.models import MODELS
from shipgym_baselines.classical.l1_backstepping import AdaptiveBackstepping, L1Backstepping
from shipgym_baselines.cli import build_parser
from shipgym_baselines.evaluation import run_episode
from shipgym_baselines.jsonout import finite_or_none
from shipgym_baselines.reproduce import PAPERS, xu2021
from shipgym_baselines.reproduce.xu2021 import controllers, current, linearised, metrics
from shipgym_baselines.reproduce.xu2021 import scenario as xu2021_scenario

pytestmark = pytest.mark.skipif("esso_osaka" not in MODELS, reason="esso_osaka not registered")

ROW_KEYS = {"case", "controller", "metric", "ours", "paper"}


@pytest.fixture(scope="module")
def short_run(tmp_path_factory):  # type: ignore[no-untyped-def]
    """L1 (filter on the command) and adaptive backstepping over 300 s (switch at 150 s)."""
    out = tmp_path_factory.mktemp("xu2021")
    rows = xu2021.REPRODUCTION.run(
        out, seeds=1, controllers=(controllers.L1, controllers.AB), time_limit=300.0, plot=False
    )
    return out, rows, {(r["case"], r["controller"], r["metric"]): r for r in rows}


def test_registered_and_cli_choice() -> None:
    assert PAPERS["xu2021"] is xu2021.REPRODUCTION
    assert build_parser().parse_args(["reproduce", "xu2021"]).paper == "xu2021"


def test_short_run_rows_markdown_and_files(short_run) -> None:  # type: ignore[no-untyped-def]
    out, rows, index = short_run
    for row in rows:
        assert ROW_KEYS <= row.keys()
        assert row["paper"] is None or isinstance(row["paper"], bool | float)
    assert json.loads((out / "xu2021.json").read_text()) == finite_or_none(rows)
    for phase in metrics.PHASES:
        for label in (controllers.L1, controllers.AB):
            assert 0 < index[(phase, label, "ace")]["ours"] < 10.0  # m, inside the corridor
    # the paper has no numbers for §5.2: only its claims and the UGAS statement carry one
    assert all(r["paper"] is None for r in rows if r["case"] in metrics.PHASES)
    assert index[("claims", controllers.L1, "reaches_goal")]["paper"] is True
    assert index[("claims", controllers.L1, "ace_ratio_to_adaptive_backstepping")]["paper"] == 1.0
    assert index[("linearised", controllers.L1, "stable")]["paper"] is True
    md = xu2021.REPRODUCTION.markdown(rows)
    assert md == (out / "xu2021.md").read_text()
    for text in (
        "**weak_current**",
        "**strong_current**",
        "**claims**",
        controllers.L1,
        controllers.AB,
    ):
        assert text in md
    assert "| ACE = mean \\|e\\| [m] |" in md  # pipes escaped inside table cells


def test_episode_figures_match_the_leaderboard_metrics() -> None:
    """The per-phase figures count the same steps as shipgym.metrics: over the whole
    episode, ACE, mean |ψ̃| and mean |δ| equal the leaderboard's metrics."""
    scenario = xu2021_scenario.build_scenario(120.0)
    recorder = controllers.Recorded(AdaptiveBackstepping(preset="paper"), controllers.AB)
    result = run_episode(recorder, scenario, 10_000)
    fig = metrics.episode_figures(scenario, result, recorder)["episode"]
    m = result.metrics
    assert fig["ace"] == pytest.approx(m["ace"], rel=1e-12)
    assert fig["std_abs_e"] == pytest.approx(m["std_abs_cross_track"], rel=1e-12)
    assert math.radians(fig["mean_abs_heading_error_deg"]) == pytest.approx(
        m["mean_abs_heading_error"], rel=1e-9
    )
    assert math.radians(fig["mean_abs_rudder_deg"]) == pytest.approx(
        m["mean_abs_rudder"], rel=1e-12
    )
    # the recorded reference error is the controller's own z1 = ψ − ψd
    assert recorder.log["ref_error"] == recorder.inner.history["z1"]


def test_filter_on_the_command_removes_its_high_frequency_content(short_run) -> None:
    """C(s) = ω²/(s² + 2ωs + ω²), ω = 0.25 rad/s, attenuates by ≥ 24 dB above 1 rad/s:
    the L1 command's RMS there is a small fraction of the unfiltered law's (measured
    0.185° vs 3.05°, 300 s), and lower above ω too (2.92° vs 4.72°) — while the rudder
    works harder overall (the linearised loop is unstable: a rudder limit cycle)."""
    _, _, index = short_run

    def ours(label: str, metric: str) -> float:
        return index[("episode", label, metric)]["ours"]

    l1, ab = controllers.L1, controllers.AB
    assert ours(l1, "command_hf1_rms_deg") < 0.2 * ours(ab, "command_hf1_rms_deg")
    assert ours(l1, "command_hf_rms_deg") < 0.8 * ours(ab, "command_hf_rms_deg")
    assert ours(l1, "mean_abs_rudder_rate_deg_s") > 2.0 * ours(ab, "mean_abs_rudder_rate_deg_s")
    assert index[("claims", l1, "command_hf1_lower_than_adaptive_backstepping")]["ours"] is True


def test_linearised_loop_of_the_paper_design(short_run) -> None:
    """With C(s) on the command the loop crosses over near 0.45 rad/s with a negative phase
    margin (−26°) and a right-half-plane pole (+0.070 1/s); without it, it is stable."""
    _, _, index = short_run
    lin = {m: index[("linearised", controllers.L1, m)]["ours"] for m in ("crossover", "stable")}
    assert lin["crossover"] == pytest.approx(0.448, abs=0.01)
    assert index[("linearised", controllers.L1, "phase_margin_deg")]["ours"] == pytest.approx(
        -26.3, abs=1.0
    )
    assert index[("linearised", controllers.L1, "max_pole_real")]["ours"] == pytest.approx(
        0.0703, abs=0.002
    )
    assert lin["stable"] is False
    assert index[("linearised", controllers.AB, "stable")]["ours"] is True


def test_loop_margins_of_an_integrator_and_a_first_order_lag() -> None:
    """L = k/s: crossover k, phase margin 90°.  L = k/(s(s + 1)), k = 2: |L(jω)| = 1 at
    ω² = (−1 + √(1 + 4k²))/2 and PM = atan(1/ω)."""
    wc, pm = linearised.loop_margins(np.array([3.0]), np.array([1.0, 0.0]))
    assert (wc, pm) == (pytest.approx(3.0, rel=1e-9), pytest.approx(90.0, abs=1e-7))
    wc, pm = linearised.loop_margins(np.array([2.0]), np.array([1.0, 1.0, 0.0]))
    w = math.sqrt((-1.0 + math.sqrt(17.0)) / 2.0)
    assert wc == pytest.approx(w, rel=1e-9)
    assert pm == pytest.approx(math.degrees(math.atan(1.0 / w)), abs=1e-7)


def test_adaptive_filter_placement_with_frozen_estimates_is_adaptive_backstepping() -> None:
    """filter_placement="adaptive" filters only δ − δ_nom: with the adaptation frozen at
    the nominal estimates that share is 0 and the commands equal the unfiltered law's."""
    scenario = xu2021_scenario.build_scenario(60.0)
    frozen = {"preset": "paper", "gamma_rho": 0.0, "gamma_sigma": 0.0, "gamma_b": 0.0}
    a = run_episode(L1Backstepping(filter_placement="adaptive", **frozen), scenario, 3)
    b = run_episode(AdaptiveBackstepping(**frozen), scenario, 3)
    c = run_episode(L1Backstepping(**frozen), scenario, 3)
    assert np.array_equal(a.trajectory["rudder_command"], b.trajectory["rudder_command"])
    assert not np.allclose(c.trajectory["rudder_command"], b.trajectory["rudder_command"])
    with pytest.raises(ValueError, match="filter_placement"):
        L1Backstepping(filter_placement="estimates")


def test_current_is_read_from_the_env_log_after_the_episode() -> None:
    """The figure's current is the env's own log, read after the episode: on the fine grid
    (h apart from t = 0, n_sub samples per step), the same under two controllers with one
    seed (its draws do not depend on the actions), from about 0.1 to about 0.2 m/s at the
    switch."""
    scenario = xu2021_scenario.build_scenario(200.0)
    logs, results = [], []
    for policy in (
        AdaptiveBackstepping(preset="paper"),
        controllers.CONTROLLERS[controllers.PID](),
    ):
        log = current.DisturbanceLog()
        results.append(run_episode(policy, scenario, 7, after_episode=log.read))
        logs.append(log.episodes[0])
    steps = min(r.metrics["steps"] for r in results)
    h = float(logs[0]["t"][1])  # the fine step
    n_sub = round(scenario.control_period / h)
    assert n_sub * h == pytest.approx(scenario.control_period, rel=1e-12)
    for log, result in zip(logs, results, strict=True):
        assert log["t"].size == result.metrics["steps"] * n_sub
        np.testing.assert_allclose(log["t"], h * np.arange(log["t"].size), atol=1e-9)
    n = steps * n_sub
    t, speed = current.current_speed(logs[0])
    np.testing.assert_array_equal(speed[:n], current.current_speed(logs[1])[1][:n])
    switch = xu2021_scenario.switch_time(scenario)
    before, after = speed[t < switch].mean(), speed[t >= switch].mean()
    assert 0.05 < before < 0.15 and 0.15 < after < 0.25

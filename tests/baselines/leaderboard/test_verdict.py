"""The verdict in two sentences, from a run's aggregate rows and episodes."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from shipgym_baselines.leaderboard.verdict import (
    folder_verdict,
    main_table,
    md_code,
    plain_name,
    recorded_verdict,
    verdict,
)

SCENARIOS = ["nomoto2_a", "nomoto2_b", "mariner_c", "blanke_d"]


def row(
    controller: str,
    iqm: float,
    ci: tuple[float, float],
    kind: str = "classical",
    failure_rate: float = 0.0,
    split: str = "catalogue",
    scenarios: list[str] | None = None,
) -> dict[str, Any]:
    """An aggregate.json object with the fields the verdict reads."""
    return {
        "controller": controller,
        "kind": kind,
        "split": split,
        "scenarios": SCENARIOS if scenarios is None else scenarios,
        "runs": 4,
        "training_seeds": 3 if kind == "learned" else 0,
        "cost_ratio_iqm": iqm,
        "cost_ratio_iqm_ci95": list(ci),
        "cost_ratio_gmean": iqm,
        "cost_ratio_gmean_ci95": list(ci),
        "prob_improvement_over_pid_los": 0.5,
        "prob_improvement_over_pid_los_ci95": [0.4, 0.6],
        "failure_rate": failure_rate,
        "failure_rate_ci95": [0.0, failure_rate],
    }


def episodes(
    controllers: list[str], failing: dict[tuple[str, str], int], seeds: int = 4
) -> list[dict[str, Any]]:
    """``seeds`` episodes per controller and scenario; ``failing``: (scenario, controller) →
    how many of them end outside the corridor (the others reach the goal)."""
    out = []
    for scenario in SCENARIOS:
        for controller in controllers:
            for k in range(seeds):
                failed = k < failing.get((scenario, controller), 0)
                out.append(
                    {
                        "controller": controller,
                        "scenario": scenario,
                        "seed": 10_000 + k,
                        "training_seed": None,
                        "termination_reason": "corridor" if failed else "goal",
                        "cost": 500.0 if failed else 100.0,
                    }
                )
    return out


NAMES = ["nmpc", "pid_los", "lqr", "ppo", "sac"]
BOARD = [
    row("nmpc", 3.266, (3.109, 3.446), failure_rate=0.25),
    row("pid_los", 3.342, (3.168, 3.527), failure_rate=0.25),
    row("lqr", 4.010, (3.795, 4.253), failure_rate=0.25),
    row("ppo", 4.830, (4.689, 4.974), kind="learned", failure_rate=0.25),
    row("sac", 11.848, (11.177, 12.581), kind="learned", failure_rate=0.3125),
    row("oddball", 2.0, (1.9, 2.1), split="catalogue:partial", scenarios=["mariner_c"]),
]
#: every controller fails 3 of 4 episodes on nomoto2_b, sac one more on mariner_c
FAILING = {("nomoto2_b", c): 3 for c in NAMES} | {("mariner_c", "sac"): 1}


def test_the_sentences_name_the_leader_the_gap_and_an_unresolved_lead() -> None:
    text = verdict(BOARD, episodes(NAMES, FAILING))
    assert text is not None
    first, second = text.split(". The ")
    assert first.startswith(
        "`nmpc` leads the 4 catalogue scenarios with a cost-ratio IQM of 3.266 [3.109, 3.446]"
    )
    # 3.342 - 3.266 = 0.076, 2.3 % of 3.342
    assert "0.076 (2.3 %) below `pid_los`'s 3.342 [3.168, 3.527]" in first
    assert "the 95 % intervals overlap, so the lead is not resolved" in first
    # ppo ranks 4th of the 5 main-table controllers; 4.830 / 3.266 = 1.48
    assert "the best learned agent, `ppo`, ranks 4th of 5 at 4.830, 1.48× the IQM" in first
    assert first.endswith("the best classical controller, `nmpc`")
    assert "oddball" not in text  # a partial table is not the verdict's
    # the median of 0.25 × 4 and 0.3125; 15 of the 16 failed episodes on nomoto2_b
    assert "The median failure rate" in text and "controllers is 25 %" in second
    assert "93.8 % of their 16 failed episodes come from `nomoto2_b`" in second
    assert second.endswith("where most controllers fail most episodes.")
    assert text.count(". ") == 1 and text.endswith(".")  # two sentences


def test_separated_intervals_say_so() -> None:
    board = [row("nmpc", 2.0, (1.9, 2.1)), row("pid_los", 3.0, (2.8, 3.2))]
    text = verdict(board, episodes(["nmpc", "pid_los"], {}))
    assert text is not None
    assert "1.000 (33.3 %) below `pid_los`'s 3.000 [2.800, 3.200]" in text
    assert ": the 95 % intervals do not overlap;" in text
    assert "not resolved" not in text


def test_a_level_lead_is_called_level() -> None:
    board = [row("a", 2.0, (1.9, 2.1)), row("b", 2.0, (1.8, 2.2))]
    text = verdict(board, episodes(["a", "b"], {}))
    assert text is not None and "level with `b` (2.000 [1.800, 2.200])" in text


def test_one_controller_no_learned_agents_no_failures() -> None:
    text = verdict([row("pid_los", 1.25, (1.2, 1.3))], episodes(["pid_los"], {}))
    assert text == (
        "`pid_los` is the only ranked controller on the 4 catalogue scenarios, with a "
        "cost-ratio IQM of 1.250 [1.200, 1.300] (1 = the oracle's cost, lower is better); no "
        "learned agent is ranked. The failure rate (episodes ending outside the corridor, "
        "non-finite or by a controller error or timeout) of `pid_los` is 0 %: none of its "
        "episodes failed."
    )
    failing = {("nomoto2_a", "pid_los"): 3, ("blanke_d", "pid_los"): 1}
    board = [row("pid_los", 1.25, (1.2, 1.3), failure_rate=0.25)]
    text = verdict(board, episodes(["pid_los"], failing))
    assert text is not None and text.endswith(
        "of `pid_los` is 25 %, and 75 % of its 4 failed episodes come from `nomoto2_a`, where "
        "it fails most episodes."
    )


def test_a_learned_leader_and_no_classical_controller() -> None:
    board = [
        row("ppo", 2.0, (1.9, 2.1), kind="learned"),
        row("pid_los", 2.5, (2.4, 2.6)),
    ]
    text = verdict(board, episodes(["ppo", "pid_los"], {}))
    assert text is not None
    assert "the best learned agent, `ppo`, ranks 1st of 2 (the leader) at 2.000, 0.80×" in text
    only = [
        row("ppo", 2.0, (1.9, 2.1), kind="learned"),
        row("td3", 3.0, (2.9, 3.1), kind="learned"),
    ]
    text = verdict(only, episodes(["ppo", "td3"], {}))
    assert text is not None and "and no classical controller is ranked" in text


def test_spread_failures_name_the_scenario_with_most() -> None:
    board = [row("a", 2.0, (1.9, 2.1), failure_rate=0.125), row("b", 3.0, (2.9, 3.1))]
    failing = {("mariner_c", "a"): 2, ("blanke_d", "a"): 1}
    text = verdict(board, episodes(["a", "b"], failing))
    assert text is not None
    assert text.endswith(
        "is 6.2 %; their 3 failed episodes are spread over 2 scenarios, the most on "
        "`mariner_c` (66.7 % of them)."
    )
    text = verdict(board, episodes(["a", "b"], {("blanke_d", "a"): 1, ("blanke_d", "b"): 2}))
    assert text is not None and text.endswith("; their 3 failed episodes are all on `blanke_d`.")


def test_no_ranking_no_verdict() -> None:
    assert verdict([], episodes(NAMES, FAILING)) is None
    partial_only = [row("x", 2.0, (1.9, 2.1), split="catalogue:partial")]
    assert verdict(partial_only, []) is None and main_table(partial_only) == []


def test_held_out_only_and_names_as_written() -> None:
    board = [
        row("a|b", 2.0, (1.9, 2.1), split="heldout"),
        row("c`d", 3.0, (2.9, 3.1), split="heldout"),
    ]
    text = verdict(board, [], md_code)
    assert text is not None and text.startswith("`a|b` leads the 4 held-out scenarios")
    assert "below `` c`d ``'s" in text
    assert text.endswith("over the 2 ranked controllers is 0 %.")  # no episodes given
    plain = verdict(board, [], plain_name)
    assert plain is not None and plain.startswith("a|b leads") and "below c`d's" in plain


def test_the_catalogue_table_is_the_verdicts() -> None:
    board = [row("h", 1.0, (0.9, 1.1), split="heldout"), row("c", 5.0, (4.9, 5.1))]
    assert [r["controller"] for r in main_table(board)] == ["c"]


def test_a_folder_without_episodes_reads_the_recorded_verdict(tmp_path: Path) -> None:
    board = [row("nmpc", 2.0, (1.9, 2.1))]
    (tmp_path / "aggregate.json").write_text(json.dumps(board))
    assert folder_verdict(tmp_path) is None  # no episodes and no leaderboard.md
    (tmp_path / "leaderboard.md").write_text("# Leaderboard\n\nThe verdict.\n\n## Ranking\n")
    assert folder_verdict(tmp_path) == "The verdict."
    (tmp_path / "leaderboard.md").write_text("# Leaderboard\n\n## Ranking\n")
    assert recorded_verdict(tmp_path / "leaderboard.md") is None
    (tmp_path / "aggregate.json").write_text("[]")
    assert folder_verdict(tmp_path) is None


@pytest.mark.parametrize("rate, text", [(0.0, "0 %"), (0.0912, "9.1 %"), (1.0, "100 %")])
def test_percentages(rate: float, text: str) -> None:
    board = [row("a", 2.0, (1.9, 2.1), failure_rate=rate)]
    out = verdict(board, [])
    assert out is not None and out.endswith(f"of `a` is {text}.")


def _with_references(base: list[dict[str, Any]], frozen: float) -> list[dict[str, Any]]:
    """``base`` and, on each of its trials, the oracle's episode (cost 100) and the frozen
    optimum's (cost ``frozen`` on nomoto2_a's trials, 100 · 1.1 elsewhere)."""
    trials = sorted({(e["scenario"], e["seed"]) for e in base})
    refs = [
        {"controller": c, "scenario": s, "seed": seed, "training_seed": None}
        | {"termination_reason": "goal", "cost": cost}
        for s, seed in trials
        for c, cost in (("oracle", 100.0), ("oracle_frozen", frozen if s == "nomoto2_a" else 110.0))
    ]
    return base + refs


def _gap(board: list[dict[str, Any]], name: str, **fields: Any) -> None:
    (r,) = [r for r in board if r["controller"] == name]
    r.update(fields)


def test_with_the_frozen_optimum_two_more_sentences_decompose_the_gap() -> None:
    board = [dict(r) for r in BOARD]
    for r in board:
        r |= {"adaptation_gain_gmean": 1.2, "adaptation_gain_gmean_ci95": [1.1, 1.3]}
        r |= {"prob_beats_frozen": 0.4, "prob_beats_frozen_ci95": [0.3, 0.5]}
        r |= {"gap_closed_iqm": 0.1, "gap_closed_iqm_ci95": [0.0, 0.2], "gap_trials": 4}
    _gap(board, "nmpc", prob_beats_frozen=0.5625, prob_beats_frozen_ci95=[0.4375, 0.6875])
    _gap(board, "nmpc", gap_closed_iqm=0.28, gap_closed_iqm_ci95=[0.2, 0.35])
    _gap(board, "lqr", gap_closed_iqm=0.4)
    # headroom 8 on nomoto2_a's 4 trials, 1.1 on the 12 others: (8^4 · 1.1^12)^(1/16) = 1.81
    text = verdict(board, _with_references(episodes(NAMES, FAILING), 800.0))
    assert text is not None
    assert text.startswith(verdict(BOARD, episodes(NAMES, FAILING)) or "?")  # the two first
    assert (
        " Knowing the change is worth 1.81× here: the cost of `oracle_frozen`, the optimum that "
        "never adapts, over `oracle`'s (geometric mean over the 16 trials of the catalogue "
        "scenarios). `nmpc`, the leader, captures 28 % [20 %, 35 %] of it (gap closed "
        "log(C_frozen / C) / log(C_frozen / C_oracle), 0 = never adapting, 1 = the oracle: its "
        "IQM over the 4 trials worth 1.2× or more) and beats the optimum that never adapts on "
        "56.2 % [43.8 %, 68.8 %] of trials; `lqr` captures the most, 40 %."
    ) in text
    assert text.count(". ") == 3 and text.endswith(".")  # four sentences


def test_no_trial_worth_the_gap_and_no_frozen_optimum() -> None:
    board = [dict(r) for r in BOARD]
    for r in board:
        r |= {"adaptation_gain_gmean": 1.0, "prob_beats_frozen": 0.5, "gap_trials": 0}
        r |= {"prob_beats_frozen_ci95": [0.25, 0.75]}
        r |= {"gap_closed_iqm": None, "gap_closed_iqm_ci95": None}
    text = verdict(board, _with_references(episodes(NAMES, FAILING), 110.0), plain_name)
    assert text is not None and text.endswith(
        "Knowing the change is worth 1.10× here: the cost of oracle_frozen, the optimum that "
        "never adapts, over oracle's (geometric mean over the 16 trials of the catalogue "
        "scenarios). No trial is worth 1.2× or more, so no gap closed is measured; the "
        "leader, nmpc, beats the optimum that never adapts on 50 % [25 %, 75 %] of trials."
    )
    # the oracle's episodes without the frozen optimum's: the two sentences only
    eps = _with_references(episodes(NAMES, FAILING), 110.0)
    eps = [e for e in eps if e["controller"] != "oracle_frozen"]
    assert verdict(BOARD, eps) == verdict(BOARD, episodes(NAMES, FAILING))


def test_a_frozen_optimum_on_some_trials_only_gives_no_gap_sentences() -> None:
    """A record whose frozen optimum lacks trials (e.g. a report merging a folder without
    it) has no gap fields (None); the verdict then states no headroom over the trials it
    happens to cover."""
    board = [dict(r) for r in BOARD]
    for r in board:
        r |= {key: None for key in ("adaptation_gain_gmean", "prob_beats_frozen")}
        r |= {"gap_closed_iqm": None, "gap_trials": None}
    eps = _with_references(episodes(NAMES, FAILING), 800.0)
    eps = [e for e in eps if e["controller"] != "oracle_frozen" or e["scenario"] == "nomoto2_a"]
    assert verdict(board, eps) == verdict(BOARD, episodes(NAMES, FAILING))

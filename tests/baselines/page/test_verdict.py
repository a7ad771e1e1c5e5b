"""The verdict in at most four sentences of at most 30 words, from a run's aggregate rows,
episodes and headroom table."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import pytest

from shipgym_baselines.page.verdict import (
    MAX_SENTENCES,
    MAX_WORDS,
    folder_verdict,
    main_table,
    md_code,
    plain_name,
    recorded_verdict,
    share_sentence,
    verdict,
    verdict_sentences,
)
from shipgym_baselines.scoring.change_share import SHARE
from shipgym_baselines.scoring.headroom import GAIN

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
    sentences = verdict_sentences(BOARD, episodes(NAMES, FAILING))
    # nmpc's and pid_los's intervals overlap: the lead is not resolved
    assert sentences[0] == (
        "`nmpc` leads the 4 catalogue scenarios at cost-ratio IQM 3.266 [3.109, 3.446], "
        "not resolved from `pid_los` (3.342 [3.168, 3.527])."
    )
    # ppo ranks 4th of the 5 main-table controllers; 4.830 / 3.266 = 1.48; the median of
    # 0.25 × 4 and 0.3125; 15 of the 16 failed episodes on nomoto2_b
    assert sentences[1] == (
        "The best learned agent, `ppo`, ranks 4th of 5 at 1.48× the leader's IQM; the median "
        "failure rate is 25 %, 93.8 % of failures on `nomoto2_b`."
    )
    assert len(sentences) == 2  # no frozen optimum: no headroom, no change share
    text = verdict(BOARD, episodes(NAMES, FAILING))
    assert text == " ".join(sentences)
    assert "oddball" not in text  # a partial table is not the verdict's


def test_separated_intervals_say_so() -> None:
    board = [row("nmpc", 2.0, (1.9, 2.1)), row("pid_los", 3.0, (2.8, 3.2))]
    text = verdict(board, episodes(["nmpc", "pid_los"], {}))
    assert text is not None
    assert ", resolved from `pid_los` (3.000 [2.800, 3.200])." in text
    assert "not resolved" not in text
    # the second's interval missing: neither resolved nor not, just ahead
    board[1]["cost_ratio_iqm_ci95"] = None
    text = verdict(board, episodes(["nmpc", "pid_los"], {}))
    assert text is not None and ", ahead of `pid_los` (3.000)." in text


def test_a_level_lead_is_called_level() -> None:
    board = [row("a", 2.0, (1.9, 2.1)), row("b", 2.0, (1.8, 2.2))]
    text = verdict(board, episodes(["a", "b"], {}))
    assert text is not None and "level with `b` (2.000 [1.800, 2.200])" in text


def test_one_controller_no_learned_agents_no_failures() -> None:
    text = verdict([row("pid_los", 1.25, (1.2, 1.3))], episodes(["pid_los"], {}))
    assert text == (
        "`pid_los` is the only ranked controller on the 4 catalogue scenarios, at IQM 1.250 "
        "[1.200, 1.300]. No learned agent is ranked; the failure rate is 0 %."
    )
    failing = {("nomoto2_a", "pid_los"): 3, ("blanke_d", "pid_los"): 1}
    board = [row("pid_los", 1.25, (1.2, 1.3), failure_rate=0.25)]
    text = verdict(board, episodes(["pid_los"], failing))
    # 3 of its 4 failed episodes on nomoto2_a
    assert text is not None and text.endswith(
        "No learned agent is ranked; the failure rate is 25 %, 75 % of failures on `nomoto2_a`."
    )


def test_a_learned_leader_and_no_classical_controller() -> None:
    board = [
        row("ppo", 2.0, (1.9, 2.1), kind="learned"),
        row("pid_los", 2.5, (2.4, 2.6)),
    ]
    text = verdict(board, episodes(["ppo", "pid_los"], {}))
    assert text is not None
    # the leader itself: its rank, no ratio to itself
    assert "The best learned agent, `ppo`, ranks 1st of 2; the median failure rate" in text
    assert "leader's IQM" not in text
    only = [
        row("td3", 3.0, (2.9, 3.1), kind="learned"),
        row("ppo", 2.0, (1.9, 2.1), kind="learned"),
    ]
    text = verdict(only, episodes(["ppo", "td3"], {}))
    assert text is not None and text.startswith("`ppo` leads")  # ranked by IQM
    assert "The best learned agent, `ppo`, ranks 1st of 2;" in text
    # a learned agent behind a classical leader: 3.0 / 2.0 = 1.50
    board = [row("pid_los", 2.0, (1.9, 2.1)), row("ppo", 3.0, (2.9, 3.1), kind="learned")]
    text = verdict(board, episodes(["ppo", "pid_los"], {}))
    assert text is not None
    assert "The best learned agent, `ppo`, ranks 2nd of 2 at 1.50× the leader's IQM;" in text


def test_spread_failures_name_the_scenario_with_most() -> None:
    board = [row("a", 2.0, (1.9, 2.1), failure_rate=0.125), row("b", 3.0, (2.9, 3.1))]
    failing = {("mariner_c", "a"): 2, ("blanke_d", "a"): 1}
    text = verdict(board, episodes(["a", "b"], failing))
    assert text is not None
    # the median of 0.125 and 0; 2 of the 3 failed episodes on mariner_c
    assert text.endswith("the median failure rate is 6.2 %, 66.7 % of failures on `mariner_c`.")
    text = verdict(board, episodes(["a", "b"], {("blanke_d", "a"): 1, ("blanke_d", "b"): 2}))
    assert text is not None and text.endswith(", 100 % of failures on `blanke_d`.")
    # a tie: the first scenario by name
    text = verdict(board, episodes(["a", "b"], {("mariner_c", "a"): 1, ("blanke_d", "b"): 1}))
    assert text is not None and text.endswith(", 50 % of failures on `blanke_d`.")


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
    assert "resolved from `` c`d `` (3.000 [2.900, 3.100])." in text
    assert text.endswith("; the median failure rate is 0 %.")  # no episodes given
    plain = verdict(board, [], plain_name)
    assert plain is not None and plain.startswith("a|b leads")
    assert "resolved from c`d (3.000" in plain


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
    assert out is not None and out.endswith(f"; the failure rate is {text}.")


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


#: headroom_table's rows: the family without a change is left out of the headroom's range
HEADROOM = [
    {"ship": "nomoto2", "family": "nominal", "scenarios": ["nomoto2_a"], "trials": 4}
    | {"headroom_gmean": 1.0},
    {"ship": "nomoto2", "family": "rudder_aging", "scenarios": ["nomoto2_b"], "trials": 4}
    | {"headroom_gmean": 2.5},
    {"ship": "mariner", "family": "current_shift", "scenarios": ["mariner_c"], "trials": 4}
    | {"headroom_gmean": 1.25},
]


def _frozen_board(shares: bool = True) -> list[dict[str, Any]]:
    """BOARD with the fields against the frozen optimum and, with ``shares``, the change
    share (the twins' fields)."""
    board = [dict(r) for r in BOARD]
    for r in board:
        r |= {GAIN: 1.2, f"{GAIN}_ci95": [1.1, 1.3]}
        r |= {"prob_beats_frozen": 0.4, "prob_beats_frozen_ci95": [0.3, 0.5]}
        r |= {"gap_closed_iqm": 0.1, "gap_closed_iqm_ci95": [0.0, 0.2], "gap_trials": 4}
        if shares:
            r |= {SHARE: 0.5, f"{SHARE}_ci95": [0.4, 0.6], "share_trials": 4}
    _gap(board, "nmpc", gap_closed_iqm=0.28, gap_closed_iqm_ci95=[0.2, 0.35])
    if shares:
        _gap(board, "nmpc", change_share_iqm=0.734, change_share_iqm_ci95=[0.72, 0.751])
        _gap(board, "ppo", change_share_iqm=0.53, change_share_iqm_ci95=[0.5, 0.56])
    return board


def test_with_the_frozen_optimum_two_more_sentences_decompose_the_gap() -> None:
    eps = _with_references(episodes(NAMES, FAILING), 800.0)
    sentences = verdict_sentences(_frozen_board(), eps, md_code, HEADROOM)
    assert sentences[:2] == verdict_sentences(BOARD, episodes(NAMES, FAILING))  # the two first
    # headroom 8 on nomoto2_a's 4 trials, 1.1 on the 12 others: (8^4 · 1.1^12)^(1/16) = 1.81;
    # its range over the families with a change: 1.25 to 2.5
    assert sentences[2] == (
        "Knowing the change is worth 1.81× over 16 trials (`oracle_frozen` over `oracle`, "
        "geometric mean), from 1.25× to 2.50× across ship × change family."
    )
    # the leader's change share, then the best learned agent's
    assert sentences[3] == (
        "Change share (0 = costs as much as never adapting, 1 = as little as the oracle): "
        "`nmpc` 0.73 [0.72, 0.75] and `ppo` 0.53 [0.50, 0.56]."
    )
    assert len(sentences) == 4
    assert verdict(_frozen_board(), eps, md_code, HEADROOM) == " ".join(sentences)
    # one headroom cell with a change: no range
    one = verdict_sentences(_frozen_board(), eps, md_code, HEADROOM[:2])
    assert one[2].endswith("(`oracle_frozen` over `oracle`, geometric mean).")
    # without the twins: the leader's gap closed, over the trials worth 1.2× or more
    bare = verdict_sentences(_frozen_board(shares=False), eps, md_code, HEADROOM)
    assert bare[:3] == sentences[:3]
    assert bare[3] == (
        "The leader closes 28 % [20 %, 35 %] of that gap (IQM over the 4 trials worth 1.2× "
        "or more)."
    )


def test_the_change_share_of_the_leader_alone_where_it_is_the_best_learned_agent() -> None:
    table = main_table(_frozen_board())
    assert share_sentence(table[3:], plain_name) == (  # ppo leads what is left
        "Change share (0 = costs as much as never adapting, 1 = as little as the oracle): "
        "ppo 0.53 [0.50, 0.56]."
    )
    # a learned agent without a share is left out; a leader without either says nothing
    table = [dict(r) for r in table]
    table[3][SHARE] = None
    assert share_sentence(table, md_code) == (
        "Change share (0 = costs as much as never adapting, 1 = as little as the oracle): "
        "`nmpc` 0.73 [0.72, 0.75]."
    )
    table[0] |= {SHARE: None, "gap_closed_iqm": None}
    assert share_sentence(table, md_code) is None


def test_no_trial_worth_the_gap_and_no_frozen_optimum() -> None:
    board = [dict(r) for r in BOARD]
    for r in board:
        r |= {GAIN: 1.0, "prob_beats_frozen": 0.5, "gap_trials": 0}
        r |= {"prob_beats_frozen_ci95": [0.25, 0.75]}
        r |= {"gap_closed_iqm": None, "gap_closed_iqm_ci95": None}
    sentences = verdict_sentences(
        board, _with_references(episodes(NAMES, FAILING), 110.0), plain_name
    )
    # no trial worth 1.2× or more: the headroom, no gap closed and no change share
    assert sentences[2:] == [
        "Knowing the change is worth 1.10× over 16 trials (oracle_frozen over oracle, "
        "geometric mean)."
    ]
    # the oracle's episodes without the frozen optimum's: the two sentences only
    eps = _with_references(episodes(NAMES, FAILING), 110.0)
    eps = [e for e in eps if e["controller"] != "oracle_frozen"]
    assert verdict(BOARD, eps) == verdict(BOARD, episodes(NAMES, FAILING))


def _sentences_of(text: str) -> list[str]:
    """A verdict's paragraph cut into sentences: after a full stop and a space, before a
    capital letter or a backtick."""
    return re.split(r"(?<=\.) (?=[A-Z`])", text)


def test_at_most_four_sentences_of_at_most_thirty_words() -> None:
    assert (MAX_SENTENCES, MAX_WORDS) == (4, 30)
    eps = _with_references(episodes(NAMES, FAILING), 800.0)
    cases = [
        (BOARD, episodes(NAMES, FAILING), ()),
        ([row("pid_los", 1.25, (1.2, 1.3))], episodes(["pid_los"], {}), ()),
        (_frozen_board(), eps, HEADROOM),
        (_frozen_board(shares=False), eps, HEADROOM),
        ([row("a", 2.0, (1.9, 2.1)), row("b", 2.0, (1.8, 2.2))], episodes(["a", "b"], {}), ()),
    ]
    four = 0
    for board, episodes_, headroom in cases:
        for code in (md_code, plain_name):
            sentences = verdict_sentences(board, episodes_, code, headroom)
            assert 2 <= len(sentences) <= MAX_SENTENCES
            four += len(sentences) == MAX_SENTENCES
            for sentence in sentences:
                assert len(sentence.split()) <= MAX_WORDS, sentence
            text = verdict(board, episodes_, code, headroom)
            assert text is not None and _sentences_of(text) == sentences
    assert four == 4  # the two cases with the frozen optimum say all four, in both codes


def test_a_frozen_optimum_on_some_trials_only_gives_no_gap_sentences() -> None:
    """A record whose frozen optimum lacks trials (e.g. a report merging a folder without
    it) has no gap fields (None); the verdict then states no headroom over the trials it
    happens to cover."""
    board = [dict(r) for r in BOARD]
    for r in board:
        r |= {key: None for key in (GAIN, "prob_beats_frozen")}
        r |= {"gap_closed_iqm": None, "gap_trials": None}
    eps = _with_references(episodes(NAMES, FAILING), 800.0)
    eps = [e for e in eps if e["controller"] != "oracle_frozen" or e["scenario"] == "nomoto2_a"]
    assert verdict(board, eps) == verdict(BOARD, episodes(NAMES, FAILING))

"""The verdict of a leaderboard run in two sentences (four with the frozen optimum).

``leaderboard.md``, ``leaderboard.html`` and the terminal summary open with them:

1. **Who leads and by how much**: the first controller of the main ranking table (the
   catalogue split's; the held-out split's when a run has no catalogue table), its
   cost-ratio IQM (C / C_oracle, 1 = the oracle's cost) and 95 % interval, the gap to the
   second and whether the two intervals overlap (then the lead is *not resolved*); and where
   the learned agents stand: the best one's rank and its IQM over the best classical
   controller's.
2. **What the failures are**: the median failure rate of the table's controllers
   (:data:`~shipgym_baselines.leaderboard.ranking.FAILED_EPISODES`), and the scenarios the failed
   episodes come from: those on which most controllers (more than half) fail most of their
   episodes (more than half), with their share of all failed episodes; when there are none,
   the scenario with the most failed episodes.

When the record has the episodes of both references (``oracle`` and ``oracle_frozen``, the
same NMPC with its truth frozen at the episode's start), two more sentences decompose it:

3. **What knowing the change is worth**: the geometric mean, over the table's trials, of
   the headroom C_frozen / C_oracle (:func:`shipgym_baselines.leaderboard.ranking.trial_headroom`).
4. **How much of it the leader captures**: its gap closed (IQM of log(C_frozen / C) /
   log(C_frozen / C_oracle) over the trials whose headroom is at least 1.2, with its 95 %
   interval) and how often it beats the optimum that never adapts (P(C < C_frozen)); and
   the controller that closes most of the gap, when that is another.

No ranking (no ``aggregate.json`` rows): no verdict.
"""

from __future__ import annotations

import json
import os
import statistics
from collections import Counter, defaultdict
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

from shipgym_baselines.leaderboard.ranking import (
    FAILED_EPISODES,
    GAP_HEADROOM,
    ORACLE,
    ORACLE_FROZEN,
    gmean_headroom,
    is_failure,
    is_partial,
    trial_headroom,
)
from shipgym_baselines.leaderboard.splits import split_label

#: the kinds the second half of the first sentence compares
LEARNED, CLASSICAL = "learned", "classical"
#: a scenario's failures are "where most controllers fail" when more than this fraction of
#: the table's controllers fail more than this fraction of their episodes on it
MOST = 0.5
#: gaps below this (cost-ratio units, the tables' 3 decimals) are reported as level
LEVEL = 5e-4
#: the file a ``report`` folder's terminal summary reads the verdict from (it has no episodes)
MARKDOWN_FILE = "leaderboard.md"
MARKDOWN_TITLE = "# Leaderboard"


def md_code(name: str) -> str:
    """``name`` as a Markdown code span on one line (a name with a backtick fenced by two)."""
    text = " ".join(name.splitlines())
    return f"`` {text} ``" if "`" in text else f"`{text}`"


def plain_name(name: str) -> str:
    """``name`` on one line, as typed (for HTML, which escapes it itself)."""
    return " ".join(name.splitlines())


def main_table(board: Sequence[Mapping[str, Any]]) -> list[Mapping[str, Any]]:
    """The rows of the table the verdict reads, ranked (IQM ascending): the catalogue split's
    main table, else the first main table of ``board``; empty without one."""
    splits = [s for s in dict.fromkeys(r["split"] for r in board) if not is_partial(s)]
    if not splits:
        return []
    split = "catalogue" if "catalogue" in splits else splits[0]
    rows = [r for r in board if r["split"] == split]
    return sorted(rows, key=lambda r: (r["cost_ratio_iqm"], r["controller"]))


def _iqm(row: Mapping[str, Any]) -> str:
    """The IQM with its interval, as the tables print it (3 decimals)."""
    text = f"{row['cost_ratio_iqm']:.3f}"
    ci = row.get("cost_ratio_iqm_ci95")
    return text + (f" [{ci[0]:.3f}, {ci[1]:.3f}]" if ci else "")


def _ordinal(n: int) -> str:
    suffix = "th" if 10 <= n % 100 <= 20 else {1: "st", 2: "nd", 3: "rd"}.get(n % 10, "th")
    return f"{n}{suffix}"


def _percent(fraction: float) -> str:
    """A fraction as a percentage with one decimal, a whole number without it: 9.1 %, 0 %."""
    text = f"{100.0 * fraction:.1f}".removesuffix(".0")
    return f"{text} %"


def _names(names: Sequence[str]) -> str:
    """ "a", "a and b", "a, b and c"."""
    return names[0] if len(names) == 1 else ", ".join(names[:-1]) + " and " + names[-1]


def _overlap(a: Mapping[str, Any], b: Mapping[str, Any]) -> bool | None:
    """Whether the two rows' IQM intervals overlap (None: one has no interval)."""
    ca, cb = a.get("cost_ratio_iqm_ci95"), b.get("cost_ratio_iqm_ci95")
    if not ca or not cb:
        return None
    return max(ca[0], cb[0]) <= min(ca[1], cb[1])


def _scope(table: Sequence[Mapping[str, Any]]) -> str:
    n = len(table[0]["scenarios"])
    split = table[0]["split"]
    label = split_label(split)
    return f"the {n} {label} scenario{'s' if n != 1 else ''}"


def lead_sentence(table: Sequence[Mapping[str, Any]], code: Callable[[str], str]) -> str:
    """Sentence 1: who leads ``table`` (ranked rows of one split), by how much, and where the
    learned agents stand."""
    first = table[0]
    leader = code(first["controller"])
    if len(table) == 1:
        text = (
            f"{leader} is the only ranked controller on {_scope(table)}, with a cost-ratio "
            f"IQM of {_iqm(first)} (1 = the oracle's cost, lower is better)"
        )
    else:
        second = table[1]
        gap = second["cost_ratio_iqm"] - first["cost_ratio_iqm"]
        head = (
            f"{leader} leads {_scope(table)} with a cost-ratio IQM of {_iqm(first)} "
            "(1 = the oracle's cost, lower is better), "
        )
        if gap < LEVEL:
            head += f"level with {code(second['controller'])} ({_iqm(second)})"
        else:
            relative = gap / second["cost_ratio_iqm"] if second["cost_ratio_iqm"] else 0.0
            head += (
                f"{gap:.3f} ({_percent(relative)}) below {code(second['controller'])}'s "
                f"{_iqm(second)}"
            )
        overlap = _overlap(first, second)
        if overlap is True:
            head += ": the 95 % intervals overlap, so the lead is not resolved"
        elif overlap is False:
            head += ": the 95 % intervals do not overlap"
        text = head
    return f"{text}; {_learned_clause(table, code)}."


def _learned_clause(table: Sequence[Mapping[str, Any]], code: Callable[[str], str]) -> str:
    learned = [(rank, r) for rank, r in enumerate(table, start=1) if r["kind"] == LEARNED]
    classical = [r for r in table if r["kind"] == CLASSICAL]
    if not learned:
        return "no learned agent is ranked"
    rank, best = learned[0]
    ranked = f"the best learned agent, {code(best['controller'])}, ranks {_ordinal(rank)} of"
    ranked += f" {len(table)}" if rank > 1 else f" {len(table)} (the leader)"
    if not classical:
        return f"{ranked}, and no classical controller is ranked"
    top = classical[0]
    ratio = best["cost_ratio_iqm"] / top["cost_ratio_iqm"] if top["cost_ratio_iqm"] else 0.0
    return (
        f"{ranked} at {best['cost_ratio_iqm']:.3f}, {ratio:.2f}× the IQM of the best "
        f"classical controller, {code(top['controller'])}"
    )


def failure_sentence(
    table: Sequence[Mapping[str, Any]],
    episodes: Sequence[Mapping[str, Any]],
    code: Callable[[str], str],
) -> str:
    """Sentence 2: the median failure rate of ``table``'s rows and the scenarios the failed
    episodes of its controllers (on its scenarios, from ``episodes``) come from."""
    what = f"({FAILED_EPISODES})"
    if len(table) == 1:
        rate = f"The failure rate {what} of {code(table[0]['controller'])} is "
        rate += _percent(table[0]["failure_rate"])
        their, most_fail = "its", "where it fails most episodes"
    else:
        median = statistics.median(r["failure_rate"] for r in table)
        rate = f"The median failure rate {what} over the {len(table)} ranked controllers is "
        rate += _percent(median)
        their, most_fail = "their", "where most controllers fail most episodes"
    controllers = {r["controller"] for r in table}
    scenarios = set(table[0]["scenarios"])
    runs: dict[tuple[str, str], list[bool]] = defaultdict(list)
    for ep in episodes:
        if ep["controller"] in controllers and ep["scenario"] in scenarios:
            runs[(ep["scenario"], ep["controller"])].append(is_failure(ep))
    failed: Counter[str] = Counter()
    for (scenario, _), outcomes in runs.items():
        failed[scenario] += sum(outcomes)
    total = sum(failed.values())
    if not runs:
        return f"{rate}."
    if total == 0:
        return f"{rate}: none of {their} episodes failed."
    most = [s for s in sorted(scenarios) if _most_fail(runs, s, controllers)]
    failures = f"{total} failed episode{'s' if total != 1 else ''}"
    if most:
        share = sum(failed[s] for s in most) / total
        return (
            f"{rate}, and {_percent(share)} of {their} {failures} come from "
            f"{_names([code(s) for s in most])}, {most_fail}."
        )
    ranked = sorted(((-n, s) for s, n in failed.items() if n), key=lambda t: t)
    if len(ranked) == 1:
        return f"{rate}; {their} {failures} are all on {code(ranked[0][1])}."
    count, top = -ranked[0][0], ranked[0][1]
    return (
        f"{rate}; {their} {failures} are spread over {len(ranked)} scenarios, the most on "
        f"{code(top)} ({_percent(count / total)} of them)."
    )


def _most_fail(
    runs: Mapping[tuple[str, str], list[bool]], scenario: str, controllers: set[str]
) -> bool:
    """Whether more than :data:`MOST` of ``controllers`` fail more than :data:`MOST` of their
    episodes on ``scenario``."""
    failing = 0
    for controller in controllers:
        outcomes = runs.get((scenario, controller), [])
        if outcomes and sum(outcomes) > MOST * len(outcomes):
            failing += 1
    return failing > MOST * len(controllers)


def _percent_interval(ci: Sequence[float] | None) -> str:
    return f" [{_percent(ci[0])}, {_percent(ci[1])}]" if ci else ""


def gap_sentences(
    table: Sequence[Mapping[str, Any]],
    episodes: Sequence[Mapping[str, Any]],
    code: Callable[[str], str],
) -> str | None:
    """Sentences 3 and 4 (module doc) for ``table`` (ranked rows of one split) from the
    episodes' headroom on its scenarios and the rows' gap fields; None without both
    references' episodes on every trial there (the rows' gap fields are None then)."""
    if table[0].get("gap_trials") is None:
        return None
    found = gmean_headroom(trial_headroom(episodes), table[0]["scenarios"])
    if found is None:
        return None
    headroom, trials = found
    label = split_label(table[0]["split"])
    worth = (
        f"Knowing the change is worth {headroom:.2f}× here: the cost of {code(ORACLE_FROZEN)}, "
        f"the optimum that never adapts, over {code(ORACLE)}'s (geometric mean over the "
        f"{trials} trial{'s' if trials != 1 else ''} of the {label} scenarios)."
    )
    leader = table[0]
    name = code(leader["controller"])
    beats = leader.get("prob_beats_frozen")
    beaten = (
        f"beats the optimum that never adapts on {_percent(beats)}"
        f"{_percent_interval(leader.get('prob_beats_frozen_ci95'))} of trials"
        if beats is not None
        else "has no comparison with the optimum that never adapts"
    )
    gap = leader.get("gap_closed_iqm")
    if gap is None:
        return (
            f"{worth} No trial is worth {GAP_HEADROOM:g}× or more, so no gap closed is "
            f"measured; the leader, {name}, {beaten}."
        )
    n = leader.get("gap_trials")
    closed = (
        f"{name}, the leader, captures {_percent(gap)}"
        f"{_percent_interval(leader.get('gap_closed_iqm_ci95'))} of it (gap closed "
        "log(C_frozen / C) / log(C_frozen / C_oracle), 0 = never adapting, 1 = the oracle: "
        f"its IQM over the {n} trials worth {GAP_HEADROOM:g}× or more) and {beaten}"
    )
    rows = [r for r in table if r.get("gap_closed_iqm") is not None]
    best = max(rows, key=lambda r: (r["gap_closed_iqm"], -table.index(r)))
    if best is not leader:
        closed += (
            f"; {code(best['controller'])} captures the most, {_percent(best['gap_closed_iqm'])}"
        )
    return f"{worth} {closed}."


def verdict(
    board: Sequence[Mapping[str, Any]],
    episodes: Sequence[Mapping[str, Any]],
    code: Callable[[str], str] = md_code,
) -> str | None:
    """The two sentences (module doc) from ``board`` (``aggregate.json`` rows) and the run's
    ``episodes`` (dicts with ``controller``, ``scenario``, ``seed``, ``termination_reason``
    and ``cost``), and two more with both references' episodes (:func:`gap_sentences`);
    ``code`` writes a controller or scenario name (default: a Markdown code span;
    :func:`plain_name` for HTML).  None without a ranking."""
    table = main_table(board)
    if not table:
        return None
    text = f"{lead_sentence(table, code)} {failure_sentence(table, episodes, code)}"
    gap = gap_sentences(table, episodes, code)
    return f"{text} {gap}" if gap else text


def folder_verdict(folder: str | os.PathLike, code: Callable[[str], str] = md_code) -> str | None:
    """The verdict of a run folder: from its ``aggregate.json`` and ``episodes.jsonl``; a
    ``report`` folder (no episodes of its own) gives the one its ``leaderboard.md`` opens
    with (written from the merged episodes)."""
    from shipgym_baselines.records.episodes import read_episodes

    folder = Path(folder)
    board = json.loads((folder / "aggregate.json").read_text())
    if not main_table(board):
        return None
    episodes = read_episodes(folder)
    if episodes:
        return verdict(board, episodes, code)
    return recorded_verdict(folder / MARKDOWN_FILE)


def recorded_verdict(markdown: Path) -> str | None:
    """The paragraph after ``leaderboard.md``'s title when it is not a heading (the verdict
    :func:`shipgym_baselines.leaderboard.ranking_markdown` writes there); None without one."""
    if not markdown.is_file():
        return None
    blocks = markdown.read_text(encoding="utf-8").split("\n\n")
    if len(blocks) < 2 or blocks[0].strip() != MARKDOWN_TITLE or blocks[1].startswith("#"):
        return None
    return blocks[1].strip()


__all__ = [
    "failure_sentence",
    "folder_verdict",
    "gap_sentences",
    "lead_sentence",
    "main_table",
    "md_code",
    "plain_name",
    "recorded_verdict",
    "verdict",
]

"""The verdict of a leaderboard run: at most four sentences of at most 30 words each.

``leaderboard.md``, ``leaderboard.html`` and the terminal summary open with them, all read
from the main ranking table (the catalogue split's; the held-out split's when a run has no
catalogue table):

1. **Who leads**: the first controller, its cost-ratio IQM (C / C_oracle, 1 = the oracle's
   cost) and 95 % interval, and whether its lead over the second is resolved (the two
   intervals do not overlap).
2. **The learned agents and the failures**: the best learned agent's rank and its IQM over
   the leader's; the median failure rate of the table's controllers
   (:data:`~shipgym_baselines.scoring.scores.FAILED_EPISODES`) and the scenario with
   the most failed episodes.

With both references' episodes (``oracle`` and ``oracle_frozen``, the same NMPC with its
truth frozen at the episode's start):

3. **What knowing the change is worth**: the geometric mean of C_frozen / C_oracle over the
   table's trials, and its range over ship × change family.
4. **Who copes with the change**: the change share of the leader and of the best learned
   agent (:mod:`~shipgym_baselines.scoring.change_share`; their gap closed when the run has no
   twins).

No ranking (no ``aggregate.json`` rows): no verdict.
"""

from __future__ import annotations

import json
import os
import statistics
from collections import Counter
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

from shipgym.scenarios.families import NOMINAL
from shipgym_baselines.privileged import ORACLE, ORACLE_FROZEN
from shipgym_baselines.scoring.change_share import SHARE
from shipgym_baselines.scoring.headroom import (
    GAP_HEADROOM,
    gmean_headroom,
    headroom_table,
    scenario_ships,
    trial_headroom,
)
from shipgym_baselines.scoring.ranking import is_partial
from shipgym_baselines.scoring.scores import is_failure
from shipgym_baselines.scoring.splits import split_label, suite_families, suite_splits

#: the kind whose best row the second sentence names
LEARNED = "learned"
#: the verdict's most sentences, and a sentence's most words
MAX_SENTENCES, MAX_WORDS = 4, 30
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
    label = split_label(table[0]["split"])
    return f"the {n} {label} scenario{'s' if n != 1 else ''}"


def lead_sentence(table: Sequence[Mapping[str, Any]], code: Callable[[str], str]) -> str:
    """Sentence 1: who leads ``table`` (ranked rows of one split), at which IQM, and whether
    the lead over the second is resolved."""
    first = table[0]
    leader = code(first["controller"])
    if len(table) == 1:
        return f"{leader} is the only ranked controller on {_scope(table)}, at IQM {_iqm(first)}."
    second = table[1]
    head = f"{leader} leads {_scope(table)} at cost-ratio IQM {_iqm(first)}"
    other = f"{code(second['controller'])} ({_iqm(second)})"
    if second["cost_ratio_iqm"] - first["cost_ratio_iqm"] < LEVEL:
        return f"{head}, level with {other}."
    overlap = _overlap(first, second)
    if overlap is True:
        return f"{head}, not resolved from {other}."
    if overlap is False:
        return f"{head}, resolved from {other}."
    return f"{head}, ahead of {other}."


def learned_sentence(
    table: Sequence[Mapping[str, Any]],
    episodes: Sequence[Mapping[str, Any]],
    code: Callable[[str], str],
) -> str:
    """Sentence 2: where the best learned agent ranks, and the failures (the median failure
    rate of ``table``'s rows and the scenario with most failed episodes, from
    ``episodes``)."""
    learned = [(rank, r) for rank, r in enumerate(table, start=1) if r["kind"] == LEARNED]
    if not learned:
        head = "No learned agent is ranked"
    else:
        rank, best = learned[0]
        ratio = best["cost_ratio_iqm"] / table[0]["cost_ratio_iqm"]
        head = f"The best learned agent, {code(best['controller'])}, ranks {_ordinal(rank)} of "
        head += f"{len(table)}" + (f" at {ratio:.2f}× the leader's IQM" if rank > 1 else "")
    return f"{head}; {failure_clause(table, episodes, code)}."


def failure_clause(
    table: Sequence[Mapping[str, Any]],
    episodes: Sequence[Mapping[str, Any]],
    code: Callable[[str], str],
) -> str:
    """The median failure rate of ``table``'s rows
    (:data:`~shipgym_baselines.scoring.scores.FAILED_EPISODES`) and the
    scenario of the table with most of their failed episodes (from ``episodes``)."""
    rates = [r["failure_rate"] for r in table]
    median = statistics.median(rates)
    text = f"the {'median ' if len(table) > 1 else ''}failure rate is {_percent(median)}"
    controllers = {r["controller"] for r in table}
    scenarios = set(table[0]["scenarios"])
    failed: Counter[str] = Counter()
    for ep in episodes:
        if ep["controller"] in controllers and ep["scenario"] in scenarios and is_failure(ep):
            failed[ep["scenario"]] += 1
    if not failed:
        return text
    top, count = min(failed.items(), key=lambda kv: (-kv[1], kv[0]))
    total = sum(failed.values())
    return f"{text}, {_percent(count / total)} of failures on {code(top)}"


def _percent_interval(ci: Sequence[float] | None) -> str:
    return f" [{_percent(ci[0])}, {_percent(ci[1])}]" if ci else ""


def _value(row: Mapping[str, Any], field: str) -> str:
    """A row's value of ``field`` with its interval, 2 decimals."""
    ci = row.get(f"{field}_ci95")
    text = f"{row[field]:.2f}"
    return text + (f" [{ci[0]:.2f}, {ci[1]:.2f}]" if ci else "")


def headroom_sentence(
    table: Sequence[Mapping[str, Any]],
    episodes: Sequence[Mapping[str, Any]],
    code: Callable[[str], str],
    headroom: Sequence[Mapping[str, Any]] = (),
) -> str | None:
    """Sentence 3: what knowing the change is worth on ``table``'s trials (the geometric
    mean of C_frozen / C_oracle) and its range over ship × change family (``headroom``:
    :func:`~shipgym_baselines.scoring.headroom.headroom_table`'s rows of the split;
    the family without a change left out); None without both references' episodes."""
    if table[0].get("gap_trials") is None:
        return None
    found = gmean_headroom(trial_headroom(episodes), table[0]["scenarios"])
    if found is None:
        return None
    worth, trials = found
    text = (
        f"Knowing the change is worth {worth:.2f}× over {trials} trial"
        f"{'s' if trials != 1 else ''} ({code(ORACLE_FROZEN)} over {code(ORACLE)}, geometric "
        "mean)"
    )
    cells = [r["headroom_gmean"] for r in headroom if r["family"] != NOMINAL]
    if len(cells) > 1:
        text += f", from {min(cells):.2f}× to {max(cells):.2f}× across ship × change family"
    return f"{text}."


def share_sentence(table: Sequence[Mapping[str, Any]], code: Callable[[str], str]) -> str | None:
    """Sentence 4: the change share of the leader and of the best learned agent (their gap
    closed where the run has no twins); None without either."""
    leader = table[0]
    learned = [r for r in table if r["kind"] == LEARNED]
    named = [leader, *([learned[0]] if learned and learned[0] is not leader else [])]
    if leader.get(SHARE) is not None:
        parts = [f"{code(r['controller'])} {_value(r, SHARE)}" for r in named if r.get(SHARE)
                 is not None]  # fmt: skip
        return (
            f"Change share (0 = costs as much as never adapting, 1 = as little as the oracle): "
            f"{_names(parts)}."
        )
    if leader.get("gap_closed_iqm") is None:
        return None
    n = leader.get("gap_trials")
    return (
        f"The leader closes {_percent(leader['gap_closed_iqm'])}"
        f"{_percent_interval(leader.get('gap_closed_iqm_ci95'))} of that gap (IQM over the {n} "
        f"trials worth {GAP_HEADROOM:g}× or more)."
    )


def verdict_sentences(
    board: Sequence[Mapping[str, Any]],
    episodes: Sequence[Mapping[str, Any]],
    code: Callable[[str], str] = md_code,
    headroom: Sequence[Mapping[str, Any]] = (),
) -> list[str]:
    """The verdict's sentences (module doc; at most :data:`MAX_SENTENCES`): who leads, where
    the learned agents stand and the failures, what knowing the change is worth and the
    change share of the leader and the best learned agent; empty without a ranking."""
    table = main_table(board)
    if not table:
        return []
    sentences = [lead_sentence(table, code), learned_sentence(table, episodes, code)]
    worth = headroom_sentence(table, episodes, code, headroom)
    if worth is not None:
        sentences.append(worth)
        share = share_sentence(table, code)
        if share is not None:
            sentences.append(share)
    return sentences


def verdict(
    board: Sequence[Mapping[str, Any]],
    episodes: Sequence[Mapping[str, Any]],
    code: Callable[[str], str] = md_code,
    headroom: Sequence[Mapping[str, Any]] = (),
) -> str | None:
    """The verdict (:func:`verdict_sentences`) as one paragraph from ``board``
    (``aggregate.json`` rows), the run's ``episodes`` (dicts with ``controller``,
    ``scenario``, ``seed``, ``termination_reason`` and ``cost``) and the ``headroom``
    table's rows; ``code`` writes a controller or scenario name (default: a Markdown code
    span; :func:`plain_name` for HTML).  None without a ranking."""
    sentences = verdict_sentences(board, episodes, code, headroom)
    return " ".join(sentences) if sentences else None


def folder_verdict(folder: str | os.PathLike, code: Callable[[str], str] = md_code) -> str | None:
    """The verdict of a run folder: from its ``aggregate.json`` and ``episodes.jsonl``; a
    ``report`` folder (no episodes of its own) gives the one its ``leaderboard.md`` opens
    with (written from the merged episodes)."""
    from shipgym_baselines.records.episodes import read_episodes
    from shipgym_baselines.records.runrecord import RUN_FILE, read_run

    folder = Path(folder)
    board = json.loads((folder / "aggregate.json").read_text())
    table = main_table(board)
    if not table:
        return None
    episodes = read_episodes(folder)
    if not episodes:
        return recorded_verdict(folder / MARKDOWN_FILE)
    headroom: list[dict[str, Any]] = []
    if (folder / RUN_FILE).is_file():
        suite = read_run(folder)["suite"]
        ships = scenario_ships(suite["scenarios"])
        families = suite_families(suite)
        headroom = headroom_table(episodes, ships, families, suite_splits(suite), table[0]["split"])
    return verdict(board, episodes, code, headroom)


def recorded_verdict(markdown: Path) -> str | None:
    """The paragraph after ``leaderboard.md``'s title when it is not a heading (the verdict
    :func:`shipgym_baselines.page.markdown.ranking_markdown` writes there); None without one."""
    if not markdown.is_file():
        return None
    blocks = markdown.read_text(encoding="utf-8").split("\n\n")
    if len(blocks) < 2 or blocks[0].strip() != MARKDOWN_TITLE or blocks[1].startswith("#"):
        return None
    return blocks[1].strip()


__all__ = [
    "folder_verdict",
    "headroom_sentence",
    "lead_sentence",
    "learned_sentence",
    "main_table",
    "md_code",
    "plain_name",
    "recorded_verdict",
    "share_sentence",
    "verdict",
    "verdict_sentences",
]

"""The ranking tables' columns, as ``leaderboard.md`` and ``leaderboard.html`` both show
them: which ``aggregate.json`` field each shows, under which header, how its cell reads
and when the column is there at all.

:data:`RANKING_COLUMNS` holds them in the page's order; :data:`MARKDOWN_ORDER` names them
in ``leaderboard.md``'s.  Each output formats a cell by its :attr:`RankingColumn.cell`
(:mod:`.markdown`: value and interval on one line; :mod:`~shipgym_baselines.page.html`: the
interval below).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Literal

from shipgym_baselines.registry import BASELINE
from shipgym_baselines.scoring.change_share import NOMINAL, SHARE
from shipgym_baselines.scoring.headroom import GAIN
from shipgym_baselines.scoring.ranking import PROB

#: how a cell reads: the row's rank in its table, the controller's name (the page: with its
#: swatch), a text, a count (a list: its length), a value with its 95 % interval
Cell = Literal["rank", "name", "text", "count", "interval"]


@dataclass(frozen=True)
class RankingColumn:
    """One column of the ranking tables: ``name`` (the page's sort key, ``data-key``),
    ``markdown`` / ``page`` its header in each (plain text; None: not in that output),
    ``cell`` how its cells read, ``field`` the ``aggregate.json`` field (its interval:
    ``<field>_ci95``; default: ``name``), ``lower``: better lower (the page sorts it
    ascending on the first click), ``digits``: the decimals of ``leaderboard.md``'s value
    and interval (the page shows 3), ``trials``: the field of the count shown beside the
    value, ``only_with``: the field without which (None in every row of a table) the
    column is left out of that table, ``long``: shown only in the page's long ranking table
    (every field of ``aggregate.json``), not in the main ranking."""

    name: str
    markdown: str | None
    page: str | None
    cell: Cell = "interval"
    field: str = ""
    lower: bool = False
    digits: int = 2
    trials: str | None = None
    only_with: str | None = None
    long: bool = False

    @property
    def key(self) -> str:
        """The ``aggregate.json`` field the column shows."""
        return self.field or self.name

    def value(self, row: Mapping[str, Any]) -> Any:
        """The row's value of this column's field (None: missing)."""
        return row.get(self.key)

    def interval(self, row: Mapping[str, Any]) -> Any:
        """The row's 95 % interval of this column's field (None: missing)."""
        return row.get(f"{self.key}_ci95")


#: the ranking tables' columns, in the page's order
RANKING_COLUMNS = (
    RankingColumn("controller", "controller", "controller", cell="name"),
    RankingColumn("rank", "rank", "rank", cell="rank"),
    RankingColumn("kind", "kind", "kind", cell="text"),
    RankingColumn("scenarios", "scenarios", "scenarios", cell="count"),
    RankingColumn("runs", None, "runs", cell="count"),
    RankingColumn("training_seeds", "training seeds", "training seeds", cell="count"),
    RankingColumn(
        "cost_ratio_iqm", "cost ratio IQM [95 % CI]", "IQM cost ratio", lower=True, digits=3
    ),
    RankingColumn(
        "cost_ratio_gmean", "geometric mean [95 % CI]", "geometric mean", lower=True, digits=3
    ),
    RankingColumn(
        "prob",
        f"P(improvement over {BASELINE}) [95 % CI]",
        f"P(ratio < {BASELINE}'s)",
        field=PROB,
        only_with=PROB,
    ),
    RankingColumn("failure_rate", "failure rate [95 % CI]", "failure rate", lower=True),
    # against the changing trials' twins: only where the run has the twins' episodes
    RankingColumn(
        NOMINAL, "nominal ratio [95 % CI]", "nominal ratio", lower=True, only_with=NOMINAL
    ),
    RankingColumn(
        SHARE,
        "change share IQM [95 % CI] (trials)",
        "change share",
        trials="share_trials",
        only_with=SHARE,
    ),
    # against the frozen optimum: only where the run has oracle_frozen's episodes; in the
    # page's long table
    RankingColumn(GAIN, None, "C_frozen / C", only_with=GAIN, long=True),
    RankingColumn("prob_beats_frozen", None, "P(C < C_frozen)", only_with=GAIN, long=True),
    RankingColumn(
        "gap_closed_iqm",
        None,
        "gap closed IQM",
        trials="gap_trials",
        only_with=GAIN,
        long=True,
    ),
)
#: the columns of ``leaderboard.md``'s ranking tables, in its order
MARKDOWN_ORDER = (
    "rank",
    "controller",
    "kind",
    "training_seeds",
    "scenarios",
    "cost_ratio_iqm",
    "cost_ratio_gmean",
    "prob",
    "failure_rate",
    NOMINAL,
    SHARE,
)


def markdown_columns() -> list[RankingColumn]:
    """The columns ``leaderboard.md`` shows, in :data:`MARKDOWN_ORDER`."""
    by_name = {c.name: c for c in RANKING_COLUMNS}
    return [by_name[name] for name in MARKDOWN_ORDER]


def page_columns(long: bool = False) -> list[RankingColumn]:
    """The columns the page's main ranking shows, in its order; ``long``: those of its long
    ranking table (every column)."""
    return [c for c in RANKING_COLUMNS if c.page is not None and (long or not c.long)]


def shown(
    columns: Iterable[RankingColumn], rows: Sequence[Mapping[str, Any]]
) -> list[RankingColumn]:
    """The columns of one table of ``rows``: each whose :attr:`~RankingColumn.only_with`
    field some row has (not None)."""
    return [
        c
        for c in columns
        if c.only_with is None or any(r.get(c.only_with) is not None for r in rows)
    ]


def count(value: Any) -> Any:
    """A count cell's number: a list's length, else the value as it is."""
    return len(value) if isinstance(value, Sequence) else value

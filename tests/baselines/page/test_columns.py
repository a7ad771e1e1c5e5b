"""The ranking tables' columns, one spec for leaderboard.md and the page."""

from __future__ import annotations

from shipgym_baselines.page.columns import (
    MARKDOWN_ORDER,
    RANKING_COLUMNS,
    count,
    markdown_columns,
    page_columns,
    shown,
)
from shipgym_baselines.scoring.change_share import NOMINAL, SHARE
from shipgym_baselines.scoring.headroom import GAIN
from shipgym_baselines.scoring.ranking import AGGREGATE_FIELDS, PROB


def test_markdown_shows_every_column_with_a_markdown_header() -> None:
    with_header = {c.name for c in RANKING_COLUMNS if c.markdown is not None}
    assert set(MARKDOWN_ORDER) == with_header
    assert [c.name for c in markdown_columns()] == list(MARKDOWN_ORDER)
    # the page's main ranking shows every column but the long ones, its long table all
    long = [c.name for c in RANKING_COLUMNS if c.long]
    assert long == [GAIN, "prob_beats_frozen", "gap_closed_iqm"]
    assert [c.name for c in page_columns()] == [
        c.name for c in RANKING_COLUMNS if c.name not in long
    ]
    assert [c.name for c in page_columns(long=True)] == [c.name for c in RANKING_COLUMNS]
    # the main tables show the twins' numbers, not those against the frozen optimum
    assert {NOMINAL, SHARE} <= set(MARKDOWN_ORDER)
    assert not set(long) & set(MARKDOWN_ORDER)


def test_every_column_shows_an_aggregate_field() -> None:
    for column in RANKING_COLUMNS:
        if column.cell != "rank":
            assert column.key in AGGREGATE_FIELDS, column.name
        if column.cell == "interval":
            assert f"{column.key}_ci95" in AGGREGATE_FIELDS, column.name


def test_a_column_that_needs_a_field_is_left_out_where_no_row_has_it() -> None:
    rows = [{PROB: None, GAIN: 1.2}, {PROB: None, GAIN: None}]
    names = [c.name for c in shown(RANKING_COLUMNS, rows)]
    assert "prob" not in names and GAIN in names and "gap_closed_iqm" in names
    names = [c.name for c in shown(RANKING_COLUMNS, [{PROB: 0.4}])]
    assert "prob" in names and GAIN not in names


def test_a_count_cell_counts_a_list() -> None:
    assert count(["a", "b"]) == 2
    assert count(3) == 3
    assert count(None) is None

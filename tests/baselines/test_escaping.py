"""Names written as text: figures draw them as typed, the Markdown
and CSV tables escape them."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import yaml

from shipgym_baselines.cli import main
from shipgym_baselines.escaping import csv_cell, md_cell, plain_text

ROOT = Path(__file__).resolve().parents[2]
MATHTEXT = r"$\undefinedmacro{x}$"
FORMULA = "=HYPERLINK(1)|x"


def cell_counts(markdown: str) -> list[list[int]]:
    """Per Markdown table, the number of cell separators (unescaped ``|``) of each line."""
    tables: list[list[int]] = []
    previous = ""
    for line in markdown.splitlines():
        if line.startswith("|"):
            if not previous.startswith("|"):
                tables.append([])
            tables[-1].append(line.replace(r"\|", "").count("|"))
        previous = line
    return tables


def test_finding5_escaping_of_one_name() -> None:
    assert plain_text(MATHTEXT) == r"\$\undefinedmacro{x}\$"
    assert md_cell("a|b\nc") == r"a\|b c"
    assert [csv_cell(v) for v in ("=1+2", "+1", "-x", "@SUM(A1)", "pid_los", -1.5)] == [
        "'=1+2",
        "'+1",
        "'-x",
        "'@SUM(A1)",
        "pid_los",
        -1.5,
    ]


def test_finding5_a_mathtext_name_is_drawn_as_typed_and_tables_escape_names(
    tmp_path: Path, capsys
) -> None:
    """A controller named in mathtext and a scenario file named in mathtext: the
    leaderboard writes every table and figure (it used to die after all episodes); in
    leaderboard.md a ``|`` in a name stays inside its cell, in leaderboard.csv a name that
    starts with ``=`` is no formula."""
    scenario = tmp_path / "named.yaml"  # the tables name it by its name:
    nominal = (ROOT / "configs/scenarios/nominal.yaml").read_text()
    scenario.write_text(nominal.replace("name: nominal", r"name: '$\undefinedmacro{y}$'"))
    suite = tmp_path / "names.yaml"
    controllers = [
        "pid_los",
        "zero_rudder",
        "oracle",  # the ranking's denominator
        {"controller": "pid_vf", "name": MATHTEXT},
        {"controller": "pid_tvvf", "name": FORMULA},
    ]
    suite.write_text(
        yaml.safe_dump(
            {"name": "names", "scenarios": [str(scenario)], "controllers": controllers, "seeds": 1}
        )
    )
    out = tmp_path / "out"
    args = ["leaderboard", "--suite", str(suite), "--out", str(out), "--workers", "1"]
    args.append("--vector-figures")  # the SVG keeps the drawn text as characters
    assert main([*args, "--no-progress", "--json"]) == 0, capsys.readouterr().err
    rows = json.loads(capsys.readouterr().out)
    assert {r["controller"] for r in rows} == {
        "pid_los",
        "zero_rudder",
        "oracle",
        MATHTEXT,
        FORMULA,
    }
    figures = sorted(p.name for p in out.glob("*.png"))
    assert figures == [
        "profile_yours.png",
        "ranking_yours.png",
        "scenario___undefinedmacro_y__.png",
    ]
    svg = (out / "ranking_yours.svg").read_text()
    assert MATHTEXT in svg  # drawn as typed (SVG text keeps the characters)
    markdown = (out / "leaderboard.md").read_text()
    assert markdown.count(r"=HYPERLINK(1)\|x") == 3  # ranking, scores, rows
    for table in cell_counts(markdown):  # every row of a table has its header's cells
        assert len(set(table)) == 1, table
    with open(out / "leaderboard.csv", newline="") as fh:
        names = {row["controller"] for row in csv.DictReader(fh)}
    assert names == {"pid_los", "zero_rudder", "oracle", MATHTEXT, "'" + FORMULA}

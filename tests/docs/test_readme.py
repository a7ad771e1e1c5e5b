"""The README is a front door: short, its links resolve, and its test command is
the one CI runs."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import pytest
import yaml

REPO = Path(__file__).resolve().parents[2]
README = (REPO / "README.md").read_text(encoding="utf-8")


def test_the_readme_is_at_most_250_lines() -> None:
    assert len(README.splitlines()) <= 250


def test_every_link_of_the_readme_resolves() -> None:
    links = re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", README)
    local = [link for link in links if not link.startswith("http")]
    assert len(local) >= 10
    for link in local:
        assert (REPO / link).is_file(), link


def test_the_readme_test_command_is_what_ci_runs() -> None:
    blocks = re.findall(r"```bash\n(.*?)```", README, flags=re.S)
    (command,) = [b.strip() for b in blocks if "pytest" in b]
    assert command in (REPO / ".ci" / "run").read_text().splitlines()


def test_the_readme_mentions_the_notebooks_and_the_docs_build() -> None:
    for notebook in (REPO / "notebooks").glob("*.ipynb"):
        assert f"notebooks/{notebook.name}" in README
    assert "python -m sphinx -W -b html docs docs/_build/html" in README


def test_the_evaluate_example_gives_the_leaderboards_episodes(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The README's ``evaluate(..., suite="default")`` prints what the default leaderboard
    records for those seeds: the leaderboard, run on a suite of that one scenario and
    controller with the default suite's trial ranges, gives the same episodes."""
    from shipgym_baselines.evaluation import EVAL_SEED_OFFSET
    from shipgym_baselines.leaderboard.run import run_leaderboard
    from shipgym_baselines.records.episodes import read_episodes
    from shipgym_baselines.suite import load_suite

    blocks = re.findall(r"```python\n(.*?)```", README, flags=re.S)
    (block,) = [b for b in blocks if "suite=" in b and "evaluate(" in b]
    call = re.search(r'evaluate\("(\w+)", "(\w+)", seeds=\[([\d, ]+)\], suite="(\w+)"\)', block)
    assert call, block
    controller, scenario, suite = call[1], call[2], call[4]
    seeds = [int(s) for s in call[3].split(",")]
    assert seeds == [EVAL_SEED_OFFSET + i for i in range(len(seeds))]  # the first trials
    spec = load_suite(suite)
    assert scenario in spec.scenarios and controller in spec.controllers
    one = {
        "name": "one",
        "scenarios": [scenario],
        "controllers": [controller],
        "seeds": len(seeds),
        "randomize": spec.randomize.model_dump(mode="json"),
    }
    (tmp_path / "one.yaml").write_text(yaml.safe_dump(one))
    run_leaderboard(
        str(tmp_path / "one.yaml"), out_dir=tmp_path / "run", workers=1, show_progress=False
    )
    episodes = read_episodes(tmp_path / "run")
    recorded = {int(e["seed"]): e for e in episodes if e["scenario"] == scenario}  # not twins
    namespace: dict[str, Any] = {"__name__": "readme"}
    capsys.readouterr()
    exec(compile(block, "README.md: the evaluate block", "exec"), namespace)
    printed = capsys.readouterr().out.strip()
    for seed, result in zip(seeds, namespace["results"], strict=True):
        assert result.metrics["ace"] == recorded[seed]["ace"]  # the same episode, bit for bit
        assert result.metrics["cost"] == recorded[seed]["cost"]
    expected = str([round(recorded[s]["ace"], 3) for s in seeds])
    assert printed == expected
    assert f"# {expected}" in block  # the numbers the README shows


def test_the_ranking_table_is_the_shipped_run_summarys() -> None:
    """The README's ranking is :func:`readme_table` of ``docs/run_summary.json`` (written by
    ``shipgym summary RUN_DIR --out docs/run_summary.json``), and the run's CPU time it
    quotes is the summary's."""
    import json

    from shipgym_baselines.leaderboard.summary import readme_table

    summary = json.loads((REPO / "docs" / "run_summary.json").read_text(encoding="utf-8"))
    assert readme_table(summary) in README
    assert summary["suite"] == "default" and summary["status"] == "complete"
    assert f"{summary['cpu_s']:,.0f} CPU s" in README
    assert f"{summary['wall_s']:,.0f} s wall" in README
    assert f"{summary['episodes']:,} episodes" in README

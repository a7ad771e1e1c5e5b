"""``shipgym scenarios``: list the scenario catalogue."""

from __future__ import annotations

import argparse

from baselines.cli.options import add_json_option, emit


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("scenarios", help="list the scenario catalogue")
    add_json_option(p, "print the names as a JSON list")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """One line per catalogue scenario: name, ship, description (``--json``: the names)."""
    from shipgym.scenarios import list_scenarios, load_scenario

    names = list_scenarios()
    lines = []
    for name in names:
        sc = load_scenario(name)
        lines.append(f"{name:28s} {sc.model.name:10s} {sc.config.description.strip()}")
    emit(args, names, "\n".join(lines))
    return 0

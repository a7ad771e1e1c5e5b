"""``shipgym scenarios``: list the scenario catalogue, or check scenario and suite files.

``--validate FILE…`` loads and checks each file and names every problem it finds (key and
YAML line): one ``ok FILE`` line per good file, one ``FILE:LINE: key 'K': message`` line per
problem of a bad one, in line order; exit code 2 when any file is bad.  An unknown key
close to a valid one is followed by "did you mean 'K'?".  A file whose top level has
``controllers``, ``scenarios``, ``heldout_scenarios`` or ``inrange_scenarios`` (or a packaged
suite's name) is checked as a suite (:func:`shipgym_baselines.suite.check_suite_file`:
its schema, every scenario it lists, every controller), any other as a scenario.  With
``--json``: a list of ``{"file", "kind", "ok", "problems"}`` (``kind``: ``scenario`` or
``suite``; ``problems``: the lines without the file name).
"""

from __future__ import annotations

import argparse
import sys

from shipgym_baselines.cli.options import add_json_option, emit

#: exit code when a validated file is bad (as a bad input elsewhere)
EXIT_BAD_FILE = 2


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "scenarios", help="list the scenario catalogue, or check scenario and suite files"
    )
    p.add_argument(
        "--validate",
        nargs="+",
        metavar="FILE",
        default=None,
        help="load and check these scenario or suite YAML files, naming every problem "
        "(exit 2 if any)",
    )
    add_json_option(p, "print the names (with --validate: one result per file) as JSON")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """One line per catalogue scenario: name, ship, description (``--json``: the names)."""
    if args.validate is not None:
        return validate(args)
    from shipgym.scenarios.loader import list_scenarios, load_scenario

    names = list_scenarios()
    lines = []
    for name in names:
        sc = load_scenario(name)
        lines.append(f"{name:28s} {sc.model.name:10s} {sc.config.description.strip()}")
    emit(args, names, "\n".join(lines))
    return 0


def validate(args: argparse.Namespace) -> int:
    """Check every ``--validate`` file; 0 when all are good, else :data:`EXIT_BAD_FILE`."""
    from shipgym.scenarios.loader import check_scenario_file
    from shipgym_baselines.suite import check_suite_file, is_suite_file

    results = []
    lines = []
    for file in args.validate:
        suite = is_suite_file(file)
        problems = check_suite_file(file) if suite else check_scenario_file(file)
        # in the file's order: the file as a whole first, then by line (stable)
        problems = sorted(problems, key=lambda p: p.line or 0)
        results.append(
            {
                "file": file,
                "kind": "suite" if suite else "scenario",
                "ok": not problems,
                "problems": [p.text() for p in problems],
            }
        )
        if not problems:
            lines.append(f"ok {file}")
        lines += [p.text(file) for p in problems]
    emit(args, results, "\n".join(lines))
    bad = sum(not r["ok"] for r in results)
    if bad:
        sys.stderr.write(f"shipgym scenarios: {bad} of {len(results)} files have problems\n")
        return EXIT_BAD_FILE
    return 0

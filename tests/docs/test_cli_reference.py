"""The command-line reference page (``docs/_ext/shipgym_docs/cli.py``) covers every command and
every option of the parser, without a Sphinx build: the generator is a pure function."""

from __future__ import annotations

import argparse
import re
import sys
from collections.abc import Iterator
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "docs" / "_ext"))

from shipgym_docs import cli  # noqa: E402
from shipgym_docs.pages import cell  # noqa: E402

from shipgym_baselines.cli import build_parser  # noqa: E402


def every_parser(
    parser: argparse.ArgumentParser, path: tuple[str, ...] = ()
) -> Iterator[tuple[tuple[str, ...], argparse.ArgumentParser]]:
    """(command path, parser) of every command, nested subcommands included (own walk, not
    the generator's)."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, child in action.choices.items():
                yield (*path, name), child
                yield from every_parser(child, (*path, name))


def command_section(text: str, path: tuple[str, ...]) -> str:
    """The generated section of one command: from its heading to the next heading."""
    heading = f"`{' '.join(('shipgym', *path))}`\n"
    start = text.index(heading)
    following = re.search(r"^#+ `shipgym", text[start + len(heading) :], flags=re.M)
    end = start + len(heading) + following.start() if following else len(text)
    return text[start:end]


def test_every_option_of_every_command_is_in_the_reference() -> None:
    parser = build_parser()
    text = cli.reference(parser)
    commands = list(every_parser(parser))
    assert {p[0] for p, _ in commands} >= {"leaderboard", "evaluate", "train", "tune", "bench"}
    checked = 0
    for path, sub in commands:
        section = command_section(text, path)
        for action in sub._actions:
            if isinstance(action, argparse._HelpAction | argparse._SubParsersAction):
                continue
            for option in action.option_strings:
                assert f"`{option}`" in section, (path, option)
                checked += 1
            if not action.option_strings:
                assert f"`{action.dest}` (positional)" in section, (path, action.dest)
            if action.help:
                assert cell(action.help).replace("<", "\\<")[:40] in section, (path, action.dest)
            if action.choices is not None and action.metavar is None:
                for choice in action.choices:
                    assert str(choice) in section, (path, action.dest, choice)
    assert checked >= 60


def test_a_row_shows_the_metavar_and_the_default() -> None:
    section = command_section(cli.reference(), ("bench",))
    assert "| `--repeats` | `REPEATS` | `5` |" in section
    assert "`{env,nmpc,identification,training,leaderboard}`"[:20] in section
    run = command_section(cli.reference(), ("run",))
    assert "| `--seed` | `SEED` | `10000` |" in run
    train = command_section(cli.reference(), ("train",))
    assert "| `--seeds`, `--seed` | `SEED …` |" in train
    assert "(not with --force)" in train  # the mutually exclusive --resume


def test_nested_subcommands_get_their_own_section() -> None:
    parser = argparse.ArgumentParser(prog="shipgym")
    sub = parser.add_subparsers(dest="command")
    outer = sub.add_parser("outer", help="an outer command")
    inner = outer.add_subparsers(dest="inner").add_parser("inner", help="an inner command")
    inner.add_argument("--deep", type=int, default=3, metavar="N", help="a deep option")
    text = cli.reference(parser)
    assert "## `shipgym outer`" in text and "### `shipgym outer inner`" in text
    assert "| `--deep` | `N` | `3` | a deep option |" in command_section(text, ("outer", "inner"))


def test_the_overview_links_the_reference_and_lists_no_options_by_hand() -> None:
    overview = (REPO / "docs" / "overview.md").read_text(encoding="utf-8")
    assert "_generated/cli/index.md" in overview
    # a command's options in its table row: the hand-written list the reference replaced
    row = re.search(r"^\| `shipgym \w+ [^`]*(--|\[)", overview, flags=re.M)
    assert row is None, f"an option list typed by hand: {row.group(0) if row else ''}"

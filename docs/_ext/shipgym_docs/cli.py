"""The command-line reference: every subcommand and option of ``shipgym``, read from its parser.

:func:`reference` walks :func:`shipgym_baselines.cli.build_parser` (nested subcommands
included) and returns one MyST page: per command its help, its usage line and a table of its
arguments (name, value, default, help).  It is a pure function of the parser, so that a test
checks the page without a Sphinx build; :func:`write` puts it at ``_generated/cli/index.md``.
"""

from __future__ import annotations

import argparse
from collections.abc import Iterator
from pathlib import Path

from shipgym_baselines.cli import build_parser
from shipgym_docs.pages import cell, table, write_text

#: width of the usage lines [characters] (fixed: the page must not depend on the terminal)
USAGE_WIDTH = 88


def subcommands(
    parser: argparse.ArgumentParser,
) -> Iterator[tuple[str, str, argparse.ArgumentParser]]:
    """(name, help, parser) of each direct subcommand of ``parser``, in ``--help``'s order."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            helps = {a.dest: a.help or "" for a in action._choices_actions}
            for name, child in action.choices.items():
                yield name, helps.get(name, ""), child


def walk(
    parser: argparse.ArgumentParser, path: tuple[str, ...] = ()
) -> Iterator[tuple[tuple[str, ...], str, argparse.ArgumentParser]]:
    """(command path, help, parser) of every command below ``parser``, depth first."""
    for name, help_text, child in subcommands(parser):
        yield (*path, name), help_text, child
        yield from walk(child, (*path, name))


def arguments(parser: argparse.ArgumentParser) -> list[argparse.Action]:
    """The documented arguments of ``parser``: all but ``--help`` and the subcommand slot."""
    return [
        a
        for a in parser._actions
        if not isinstance(a, argparse._HelpAction | argparse._SubParsersAction)
    ]


def _text(value: str) -> str:
    """Help text in a table cell: ``<`` and ``*`` escaped (not HTML, not emphasis)."""
    return cell(value).replace("<", "\\<").replace("*", "\\*")


def value_of(action: argparse.Action) -> str:
    """What the argument takes: its metavar or choices, repeated per ``nargs``; ``—`` for a
    flag."""
    if action.nargs == 0:
        return "—"
    if action.metavar is not None:
        name = str(action.metavar)
    elif action.choices is not None:
        name = "{" + ",".join(str(c) for c in action.choices) + "}"
    else:
        name = action.dest.upper() if action.option_strings else action.dest
    if action.nargs in ("+", "*"):
        return f"`{name} …`" if action.nargs == "+" else f"`[{name} …]`"
    if action.nargs == "?":
        return f"`[{name}]`"
    if isinstance(action.nargs, int) and action.nargs > 1:
        return "`" + " ".join([name] * action.nargs) + "`"
    return f"`{name}`"


def default_of(action: argparse.Action) -> str:
    """The default as parsed (``—``: none; a flag's: off)."""
    if not action.option_strings or action.default is argparse.SUPPRESS:
        return "—"
    if action.nargs == 0 and action.default is False:
        return "off"
    if action.default is None:
        return "—"
    if isinstance(action.default, list | tuple):
        return "`" + " ".join(str(v) for v in action.default) + "`"
    return f"`{action.default}`"


def help_of(parser: argparse.ArgumentParser, action: argparse.Action) -> str:
    """The argument's help (``%(default)s`` expanded) and the options it excludes."""
    text = parser._get_formatter()._expand_help(action) if action.help else ""
    excluded = [
        option
        for group in parser._mutually_exclusive_groups
        if action in group._group_actions
        for other in group._group_actions
        if other is not action
        for option in other.option_strings[:1]
    ]
    if excluded:
        text += f" (not with {', '.join(excluded)})"
    return _text(text.strip()) or "—"


def usage(parser: argparse.ArgumentParser) -> str:
    """The usage line, wrapped at :data:`USAGE_WIDTH` whatever the terminal."""
    formatter = argparse.HelpFormatter(parser.prog, width=USAGE_WIDTH)
    formatter.add_usage(parser.usage, parser._actions, parser._mutually_exclusive_groups)
    return formatter.format_help().strip()


def section(path: tuple[str, ...], help_text: str, parser: argparse.ArgumentParser) -> str:
    """One command's section: heading, help, usage and the table of its arguments."""
    command = " ".join(("shipgym", *path))
    level = "#" * min(len(path) + 1, 6)
    anchor = "cli-" + "-".join(path)
    rows = [
        (
            ", ".join(f"`{o}`" for o in a.option_strings) or f"`{a.dest}` (positional)",
            value_of(a),
            default_of(a),
            help_of(parser, a),
        )
        for a in arguments(parser)
    ]
    parts = [f"({anchor})=\n{level} `{command}`\n"]
    if help_text:
        parts.append(_text(help_text[:1].upper() + help_text[1:]) + ".\n")
    parts.append("```text\n" + usage(parser) + "\n```\n")
    if rows:
        parts.append(table(["argument", "value", "default", "help"], rows))
    return "\n".join(parts)


def reference(parser: argparse.ArgumentParser | None = None) -> str:
    """The whole command-line reference of ``parser`` (default: ``shipgym``'s) as MyST."""
    parser = parser if parser is not None else build_parser()
    commands = list(walk(parser))
    index = table(
        ["command", "does"],
        [
            (f"[`{' '.join(('shipgym', *p))}`](#cli-{'-'.join(p)})", _text(h))
            for p, h, _ in commands
        ],
    )
    head = (
        "# Command-line reference\n\n"
        "Every command and option of `shipgym`, generated from its parser "
        "(`shipgym_baselines.cli.build_parser`) at each docs build: this page is the "
        "parser.  A default `—` means none: the help says what is used then.  "
        "`--json` prints one JSON document on stdout; progress goes to stderr.\n\n"
    )
    top = arguments(parser)
    body = [section(p, h, child) for p, h, child in commands]
    if top:  # options of the top-level parser itself (none today)
        body.insert(0, section((), "", parser))
    return head + index + "\n" + "\n".join(body)


def write(root: Path) -> list[Path]:
    return [write_text(root / "cli" / "index.md", reference())]

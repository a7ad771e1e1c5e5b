"""Numbers quoted in prose about run time or ranks, and the registry that records them.

A run time (``521 s wall``, ``1,028 CPU s``, ``≈ 17 CPU minutes``) or a rank (``rank 3``,
``#1``, ``14th of 18``) typed into the README or a page of ``docs/`` is a measurement: it must
be recorded in ``docs/measurements.json`` with the command, commit and machine that produced
it.  :func:`quotes` finds every such number in a Markdown text (prose only: not code blocks,
not table rows); :func:`unrecorded` lists those the registry lacks, which a test asserts is
empty (``tests/docs/test_measurements.py``).  :func:`write` renders the registry as the page
``_generated/measurements/index.md``.

A sentence is *about run time* when it names CPU or wall time or says something took, costs
or was measured (:data:`RUN_TIME_WORDS`); every number with a time unit in it
(:data:`DURATION`) is then quoted.  Ranks are quoted wherever they stand (:data:`RANK`).
A duration after ``=``, ``<`` or ``>`` is a setting or a bound (``Ts = 0.2 s``), not quoted.
Numbers that are targets or settings, not measurements, are listed in the registry's
``not_measurements`` (each a phrase with its reason).
"""

from __future__ import annotations

import dataclasses
import json
import re
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import Any

from shipgym_docs.pages import cell, table, write_text

#: the registry, beside the pages
REGISTRY = Path(__file__).resolve().parents[2] / "measurements.json"
#: the checkout (the README is quoted too)
REPO = REGISTRY.parents[1]
#: the texts whose prose is checked, relative to the checkout
CHECKED = ("README.md", "docs/*.md")

#: a number: digits with optional thousands commas and decimals
NUMBER = r"\d{1,3}(?:,\d{3})+(?:\.\d+)?|\d+(?:\.\d+)?"
#: a duration: a number (or a range "2–5") with a time unit, "CPU" or "wall" between allowed
DURATION = re.compile(
    rf"(?<![\w.])(?<![=<>]\s)(?<![=<>])(?P<low>{NUMBER})(?:\s*[–-]\s*(?P<high>{NUMBER}))?\s*"
    r"(?:CPU\s+|wall\s+)?"
    r"(?P<unit>ms|µs|us|s|sec|seconds?|min|minutes?|h|hours?)(?![\w²³])"
)
#: a rank: "rank 3", "ranks 14th", "#13", "14th of 18", "ranked 17th"
RANK = re.compile(
    r"(?:\branks?\s+(?:#\s*)?(?P<a>\d+)(?:st|nd|rd|th)?\b"
    r"|(?<![\w&])#(?P<b>\d+)\b"
    r"|\b(?P<c>\d+)(?:st|nd|rd|th)\s+(?:of|on|place|best|worst)\b"
    r"|\branked\s+(?P<d>\d+)(?:st|nd|rd|th)\b)"
)
#: words that make a sentence about run time
RUN_TIME_WORDS = re.compile(
    r"\bCPU\b|\bwall\b|wall[- ]clock|\btook\b|\btakes?\b|\btaking\b|\bcosts?\b|\bmeasured\b"
    r"|\bspends?\b|\bspent\b|\bruns? in\b|\bbuild\b|\bETA\b|\bfaster\b|\bslower\b",
    flags=re.I,
)
#: a sentence ends at . ! ? followed by a space and a capital, a backtick or a bracket
SENTENCE_END = re.compile(r"(?<=[.!?])\s+(?=[A-Z`(\[*])")


@dataclasses.dataclass(frozen=True)
class Quote:
    """One number quoted in prose: where, what kind, the value and its sentence."""

    file: str
    line: int
    kind: str  # "time" | "rank"
    value: float
    unit: str  # "s", "ms", "µs", "min", "h" (a rank: "")
    text: str  # the matched words, e.g. "1,028 CPU s"
    sentence: str


def value_of(number: str) -> float:
    """``"1,028"`` -> 1028.0."""
    return float(number.replace(",", ""))


#: a time unit as written -> its short form
UNITS = {"us": "µs", "sec": "s", "second": "s", "seconds": "s", "minute": "min"}
UNITS |= {"minutes": "min", "hour": "h", "hours": "h"}


def unit_of(word: str) -> str:
    """``"minutes"`` -> ``"min"``, ``"seconds"`` -> ``"s"``, ``"us"`` -> ``"µs"``."""
    return UNITS.get(word, word)


def parse_value(text: str) -> tuple[float, str]:
    """A registry value: ``"1,028 s"`` -> (1028.0, "s"), ``"0.3 ms"``, ``"17 min"``; a bare
    number (a rank) -> (value, "")."""
    match = re.fullmatch(rf"\s*({NUMBER})\s*(\S*)\s*", str(text))
    if match is None:
        raise ValueError(f"a registry value is 'NUMBER UNIT' or a rank, got {text!r}")
    return value_of(match.group(1)), unit_of(match.group(2))


def prose_lines(text: str) -> Iterator[tuple[int, str]]:
    """(line number, line) of the prose of a Markdown text: fenced code blocks (``` and ~~~),
    table rows, HTML comments and MyST targets ``(name)=`` left out (a ``:::`` admonition's
    text is prose)."""
    fence: str | None = None
    for number, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        match = re.match(r"(`{3,}|~{3,})", stripped)
        if match:
            if fence is None:
                fence = match.group(1)
            elif stripped == fence[0] * len(stripped) and len(stripped) >= len(fence):
                fence = None
            continue
        if fence is not None:
            continue
        if stripped.startswith(("|", "<!--", ":::")) or re.fullmatch(r"\([\w-]+\)=", stripped):
            continue
        yield number, line


def sentences(text: str) -> Iterator[tuple[int, str]]:
    """(first line, sentence) of the prose: paragraphs joined, split at sentence ends."""
    paragraph: list[tuple[int, str]] = []
    last = 0

    def flush() -> Iterator[tuple[int, str]]:
        if not paragraph:
            return
        joined = ""
        starts: list[tuple[int, int]] = []  # (offset in joined, line number)
        for number, line in paragraph:
            starts.append((len(joined), number))
            joined += line.strip() + " "
        offset = 0
        for part in SENTENCE_END.split(joined):
            at = joined.index(part, offset)
            line = max(n for o, n in starts if o <= at) if starts else 0
            offset = at + len(part)
            if part.strip():
                yield line, part.strip()

    for number, line in prose_lines(text):
        new_item = re.match(r"\s*([-*+]|\d+\.)\s", line) or line.lstrip().startswith("#")
        if not line.strip() or number != last + 1 or new_item:
            yield from flush()
            paragraph = []
        if line.strip():
            paragraph.append((number, line))
        last = number
    yield from flush()


def quotes(text: str, file: str = "") -> list[Quote]:
    """Every run-time and rank number quoted in the prose of ``text``."""
    found = []
    for line, sentence in sentences(text):
        plain = sentence.replace("\u202f", " ").replace("\u00a0", " ")
        if RUN_TIME_WORDS.search(plain):
            for match in DURATION.finditer(plain):
                for part in ("low", "high"):
                    if match.group(part):
                        value = value_of(match.group(part))
                        unit = unit_of(match.group("unit"))
                        quote = Quote(file, line, "time", value, unit, match.group(0), sentence)
                        found.append(quote)
        for match in RANK.finditer(plain):
            number = next(g for g in match.groups() if g is not None)
            found.append(Quote(file, line, "rank", float(number), "", match.group(0), sentence))
    return found


def checked_files(root: Path = REPO) -> list[Path]:
    """The README and the hand-written pages of ``docs/``."""
    files: list[Path] = []
    for pattern in CHECKED:
        files += sorted(root.glob(pattern))
    return files


def load(path: Path = REGISTRY) -> dict[str, Any]:
    """The registry: ``{"measurements": [...], "not_measurements": [...]}``."""
    return json.loads(path.read_text(encoding="utf-8"))


def _covers(entry: dict[str, Any], quote: Quote) -> bool:
    return (
        entry.get("kind", "time") == quote.kind
        and quote.file in entry.get("quoted_in", [])
        and (quote.value, quote.unit) in {parse_value(v) for v in entry.get("values", [])}
    )


def _excused(entry: dict[str, Any], quote: Quote) -> bool:
    return quote.text in entry["phrase"] and entry["phrase"] in quote.sentence


def unrecorded(quoted: Iterable[Quote], registry: dict[str, Any]) -> list[Quote]:
    """The quotes no measurement records (same kind, value and unit, the quote's file among
    its ``quoted_in``) and no ``not_measurements``
    entry excuses (its ``phrase`` holds the quoted words and stands in the sentence)."""
    measured = registry.get("measurements", [])
    excused = registry.get("not_measurements", [])
    return [
        q
        for q in quoted
        if not any(_covers(m, q) for m in measured) and not any(_excused(e, q) for e in excused)
    ]


def check(root: Path = REPO, path: Path = REGISTRY) -> list[Quote]:
    """The unrecorded quotes of every checked file under ``root``."""
    registry = load(path)
    out: list[Quote] = []
    for file in checked_files(root):
        text = file.read_text(encoding="utf-8")
        out += unrecorded(quotes(text, file.relative_to(root).as_posix()), registry)
    return out


def _values(entry: dict[str, Any]) -> str:
    return ", ".join(str(v) for v in entry["values"])


def page(registry: dict[str, Any]) -> str:
    """The registry as a page: one row per measurement."""
    rows = [
        (
            e["id"],
            _values(e),
            e.get("what", ""),
            f"`{e['command']}`" if e.get("command") else "—",
            e.get("commit", "—"),
            e.get("machine", "—"),
        )
        for e in registry.get("measurements", [])
    ]
    excused = [(e["phrase"], e["reason"]) for e in registry.get("not_measurements", [])]
    return (
        "# Recorded measurements\n\n"
        "Every run time and rank the README and these pages quote in prose, as recorded in "
        "`docs/measurements.json` (a test checks that no such number is typed without an "
        "entry: [About these pages](../../docs-site.md#numbers-in-the-prose)).\n\n"
        + table(["id", "values", "what", "command", "commit", "machine"], rows)
        + "\n## Numbers that are not measurements\n\n"
        + table(["phrase", "why"], [tuple(cell(v) for v in r) for r in excused])
    )


def write(root: Path) -> list[Path]:
    return [write_text(root / "measurements" / "index.md", page(load()))]

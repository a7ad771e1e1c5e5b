"""The page's sortable tables: escaped text, cells with their intervals and sort keys,
the controllers' swatches, the table's HTML and its packed body
(:mod:`~shipgym_baselines.page.html`)."""

from __future__ import annotations

import base64
import gzip
import html
import itertools
import math
import re
from collections.abc import Iterable, Sequence
from typing import Any, NamedTuple

from shipgym_baselines.plots.style import controller_style

#: most significant digits of a cell's sort key (``data-sort``)
SORT_DIGITS = 7


def esc(text: Any) -> str:
    """HTML-escaped text (quotes too: safe in attributes)."""
    return html.escape(str(text), quote=True)


def finite_number(value: Any) -> float | None:
    if isinstance(value, bool) or not isinstance(value, int | float):
        return None
    return float(value) if math.isfinite(value) else None


def number_text(value: Any) -> str:
    """A number for a cell: 3 significant decimals, ∞ as "never" (t_c), none as "–"."""
    if isinstance(value, int | float) and not isinstance(value, bool):
        if math.isinf(value):
            return "never" if value > 0 else "−∞"
        if math.isnan(value):
            return "–"
        return f"{value:.3f}" if isinstance(value, float) else str(value)
    return "–" if value is None else str(value)


def _interval(ci: Any) -> str:
    if isinstance(ci, Sequence) and len(ci) == 2 and all(finite_number(v) is not None for v in ci):
        return f"[{ci[0]:.3f}, {ci[1]:.3f}]"
    return ""


class Td(NamedTuple):
    """A body cell: its inner HTML, its sort value (a finite number; None sorts last; for a
    text cell unused: the script sorts by the text), the number its text starts with (what
    the script reads without ``data-sort``) and further attributes."""

    html: str
    value: float | None = None
    shown: float | None = None
    attrs: str = ""


def leading_number(text: str) -> float | None:
    """The number ``parseFloat`` reads at the start of a cell's text (None: NaN)."""
    match = _LEADING_NUMBER.match(text)
    return float(match.group(0)) if match else None


_LEADING_NUMBER = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?")


def value_cell(value: Any, ci: Any = None, std: Any = None, shade: bool = False) -> Td:
    """A numeric cell: the value, its interval (or ± std) below, the value as sort key."""
    sort = finite_number(value)
    extra = _interval(ci) or (f"± {std:.3f}" if finite_number(std) is not None else "")
    style = f' style="background:{_shade(sort)}"' if shade and sort is not None else ""
    small = f"<i>{esc(extra)}</i>" if extra else ""
    text = number_text(value)
    return Td(f"{esc(text)}{small}", sort, leading_number(text), style)


def _shade(ratio: float) -> str:
    """Background of a cost-ratio cell: green (≤ 1, the oracle) → yellow → red (≥ 4), on a
    log scale."""
    t = min(max(math.log(ratio) / math.log(4.0), 0.0), 1.0) if ratio > 0 else 0.0
    return f"hsl({120 * (1.0 - t):.0f},65%,88%)"


def text_cell(text: Any) -> Td:
    return Td(esc(text))


def swatch_class(name: str) -> tuple[str, str]:
    """(class, CSS rule) of a controller's swatch: its line's colour and style."""
    style = controller_style(name)
    border = {"-": "solid", "--": "dashed", "-.": "dashed", ":": "dotted"}.get(
        style.linestyle, "solid"
    )
    cls = "k" + "".join(c for c in style.color if c.isalnum()).lower() + border[:2]
    return cls, f".{cls}{{border-top-style:{border};border-top-color:{esc(style.color)}}}"


def swatch_css(names: Iterable[str]) -> str:
    """The swatch classes of these controllers, each rule once."""
    return "".join(sorted({swatch_class(n)[1] for n in names}))


def name_cell(name: str) -> Td:
    return Td(f'<span class="{swatch_class(name)[0]}"></span>{esc(name)}')


def _head(columns: Iterable[tuple[str, str, str]]) -> str:
    """``<thead>`` of (key, header text, "number" | "lower" | "text") columns (``lower``: a
    number that is better lower, sorted ascending on the first click); the first is the
    name."""
    cells = []
    for i, (key, text, kind) in enumerate(columns):
        first = ' data-first="ascending"' if kind == "lower" else ""
        cells.append(
            f'<th data-key="{esc(key)}" data-type="{"number" if kind == "lower" else kind}"'
            + first
            + (' class="text"' if kind == "text" and i else "")
            + f">{text}</th>"
        )
    return "<thead><tr>" + "".join(cells) + "</tr></thead>"


def _same_order(values: Sequence[float | None], keys: Sequence[float | None]) -> bool:
    """Whether ``keys`` sort the cells as ``values`` do: equal values equal keys, distinct
    ones in the same order, None (last) where None."""
    pairs = sorted({(v, k) for v, k in zip(values, keys, strict=True) if v is not None})
    if any((v is None) != (k is None) for v, k in zip(values, keys, strict=True)):
        return False
    for (v0, k0), (v1, k1) in itertools.pairwise(pairs):
        if v0 == v1 or k0 is None or k1 is None or not k0 < k1:
            return False
    return True


def sort_keys(values: Sequence[float | None], shown: Sequence[float | None]) -> list[str] | None:
    """A numeric column's ``data-sort`` keys: None where the numbers its cells' texts start
    with sort them as their values do (the script reads the text), else each value at the
    fewest significant digits that keep the values' order and ties, at most 7 (values that
    differ only beyond the 7th digit tie, and keep their order in the page; "" for none)."""
    if _same_order(values, shown):
        return None
    for digits in range(1, SORT_DIGITS + 1):
        keys = ["" if v is None else f"{v:.{digits}g}" for v in values]
        if _same_order(values, [float(k) if k else None for k in keys]):
            break
    return keys


def html_table(
    table_id: str,
    columns: Sequence[tuple[str, str, str]],
    body: Sequence[Sequence[Td]],
    compact: bool = False,
    cls: str = "",
) -> str:
    """A sortable table; ``compact``: intervals beside the values, not below.  A numeric
    column carries ``data-sort`` keys only where its texts would sort otherwise
    (:func:`sort_keys`); the script sorts a text column by its texts."""
    keys: dict[int, list[str]] = {}
    for col, (_, _, kind) in enumerate(columns):
        if kind == "text":
            continue
        cells = [(row, row[col]) for row in body if col < len(row)]
        found = sort_keys([c.value for _, c in cells], [c.shown for _, c in cells])
        if found is not None:
            keys[col] = found
    where = {col: 0 for col in keys}
    rows = []
    for row in body:
        tds = []
        for col, td in enumerate(row):
            sort = ""
            if col in keys:
                sort = f' data-sort="{keys[col][where[col]]}"'
                where[col] += 1
            tds.append(f"<td{sort}{td.attrs}>{td.html}</td>")
        rows.append("<tr>" + "".join(tds) + "</tr>")
    classes = " ".join(c for c in ("sortable", "compact" if compact else "", cls) if c)
    return (
        f'<div class="scroll"><table class="{classes}" id="{esc(table_id)}">{_head(columns)}'
        f"<tbody>{''.join(rows)}</tbody></table></div>"
    )


def packed_body(table: str) -> str:
    """``table`` (:func:`html_table`'s HTML) with its body's rows deflated into the body's
    ``data-gzip`` attribute (gzip, base64; the page's script unpacks them with the
    browser's ``DecompressionStream``): the long table's markup is ≈ 6 times lighter."""
    head, sep, rest = table.partition("<tbody>")
    inner, end, tail = rest.partition("</tbody>")
    if not sep or not end:
        raise ValueError("packed_body: the table has no <tbody>")
    packed = gzip.compress(inner.encode("utf-8"), compresslevel=9, mtime=0)
    data = base64.b64encode(packed).decode("ascii")
    return f'{head}<tbody data-gzip="{data}"></tbody>{tail}'


def unpacked_body(table: str) -> str:
    """The inverse of :func:`packed_body` (tests, and readers of the page's source)."""
    match = re.search(r'<tbody data-gzip="([A-Za-z0-9+/=]*)"></tbody>', table)
    if match is None:
        return table
    inner = gzip.decompress(base64.b64decode(match.group(1))).decode("utf-8")
    return table[: match.start()] + f"<tbody>{inner}</tbody>" + table[match.end() :]

"""The page's figures: the ranking figures embedded as data URIs (a light WebP or PNG, else
the SVG), the scenario figures linked as the files beside the page (:data:`LINKED_KINDS`),
a scenario figure's legends as text below it, the ranking and the scenario figures'
sections (:mod:`~shipgym_baselines.page.html`)."""

from __future__ import annotations

import base64
import io
import json
import os
from collections.abc import Iterable
from pathlib import Path
from typing import NamedTuple
from urllib.parse import quote

from shipgym_baselines.page.cells import esc, swatch_class
from shipgym_baselines.plots.curves import LEARNING_CURVES_STEM
from shipgym_baselines.plots.files import LEGEND_KEY, LEGEND_TOP_KEY, figure_stem
from shipgym_baselines.plots.style import controller_style
from shipgym_baselines.privileged import ORACLE, ORACLE_FROZEN


def anchor(name: str) -> str:
    """The id of a scenario's figure (the stem
    :func:`shipgym_baselines.plots.scenarios.plot_scenario` gives
    its files)."""
    return "scenario_" + figure_stem(name)


class PageImage(NamedTuple):
    """A figure as the page embeds it: MIME type, bytes, and the legends it carries as text
    (a scenario figure's :data:`~shipgym_baselines.plots.files.LEGEND_KEY`; None: in the
    image)."""

    mime: str
    data: bytes
    legends: list[tuple[str, list[tuple[str, str]]]] | None = None


def png_legends(png: Path) -> tuple[list[tuple[str, list[tuple[str, str]]]] | None, float]:
    """A scenario figure's legends (:data:`LEGEND_KEY`) and the fraction of its height
    above them (:data:`LEGEND_TOP_KEY`); (None, 1.0) for a figure without."""
    from PIL import Image

    with Image.open(png) as image:
        text = dict(getattr(image, "text", {}))
    if LEGEND_KEY not in text or LEGEND_TOP_KEY not in text:
        return None, 1.0
    legends = [(t, [tuple(e) for e in entries]) for t, entries in json.loads(text[LEGEND_KEY])]
    return legends, float(text[LEGEND_TOP_KEY])


def page_image(png: Path) -> PageImage:
    """A PNG as the page embeds it: the same pixels as lossless WebP where that is smaller
    (a palette figure: ≈ 20 % smaller; every current browser shows WebP; effort 4 of 6:
    0.1 s a figure, 2 % larger than 6 at 60 times its CPU), else the PNG as it is.  A
    scenario figure whose PNG says where its legends start
    (:data:`~shipgym_baselines.plots.files.LEGEND_TOP_KEY`) is cut above them and its
    legends returned as text (the page writes them under the image)."""
    data = png.read_bytes()
    from PIL import Image, features

    with Image.open(png) as image:
        image.load()
        text = dict(getattr(image, "text", {}))
        legends = None
        if LEGEND_KEY in text and LEGEND_TOP_KEY in text:
            legends = [
                (t, [tuple(e) for e in entries]) for t, entries in json.loads(text[LEGEND_KEY])
            ]
            top = round(float(text[LEGEND_TOP_KEY]) * image.height)
            image = image.crop((0, 0, image.width, top))
        if not features.check("webp"):
            if legends is None:
                return PageImage("image/png", data)
            out = io.BytesIO()
            image.save(out, format="PNG", optimize=True)
            return PageImage("image/png", out.getvalue(), legends)
        out = io.BytesIO()
        image.save(out, format="WEBP", lossless=True, quality=100, method=4)
    webp = out.getvalue()
    if legends is None and len(webp) >= len(data):
        return PageImage("image/png", data)
    return PageImage("image/webp", webp, legends)


class _Embedded(NamedTuple):
    uri: str
    file: str
    legends: list[tuple[str, list[tuple[str, str]]]] | None
    #: a linked figure: its (width, height) [px] and the fraction of the height shown (the
    #: page hides the legends drawn below it; they are text under it)
    size: tuple[int, int] | None = None
    shown: float = 1.0


#: the figures the page links as files beside it (the page's folder) rather than embeds:
#: one per scenario, 60 in the default run, 4 of its 4.8 MB when embedded
LINKED_KINDS = ("scenario",)


def _linked(f: Path, folder: Path) -> _Embedded:
    """A PNG beside the page, as the page links it: its path from ``folder``."""
    from PIL import Image

    legends, top = png_legends(f)
    with Image.open(f) as image:
        size = image.size
    uri = Path(os.path.relpath(f.resolve(), folder.resolve())).as_posix()
    return _Embedded(quote(uri), f.name, legends, size, top)


def embedded_figures(
    figures: Iterable[str | Path], folder: str | Path | None = None
) -> dict[str, _Embedded]:
    """stem → (data URI, file name, legends) of each figure, the PNG where a stem has one (a
    page-sized palette PNG, :func:`shipgym_baselines.plots.files.write_page_png`, embedded
    as :func:`page_image` gives it: the page stays light), else the SVG; in the
    order of ``figures``.  ``folder``: the page's; a scenario figure's PNG is then linked
    by its path from there (:func:`_linked`) instead of embedded."""
    by_stem: dict[str, Path] = {}
    for f in map(Path, figures):
        if f.suffix.lower() not in (".svg", ".png"):
            continue
        if f.stem not in by_stem or f.suffix.lower() == ".png":
            by_stem[f.stem] = f
    out = {}
    for stem, f in by_stem.items():
        linked = folder is not None and stem.partition("_")[0] in LINKED_KINDS
        if linked and f.suffix.lower() == ".png":
            out[stem] = _linked(f, Path(folder))
            continue
        if f.suffix.lower() == ".png":
            image = page_image(f)
        else:
            image = PageImage("image/svg+xml", f.read_bytes())
        data = base64.b64encode(image.data).decode("ascii")
        out[stem] = _Embedded(f"data:{image.mime};base64,{data}", f.name, image.legends)
    return out


#: the oracle's line in the scenario figures (black, dashed) and the frozen optimum's (its
#: grey, dash-dotted: dashed here, CSS has no dash-dot), as legend swatches
_REFERENCE_SWATCH = "kref"
_FROZEN_SWATCH = "kfrozen"


def reference_css() -> str:
    """The CSS of the two reference swatches (the frozen optimum's colour read from its
    registration when the page is written, so importing the page loads no controller)."""
    return (
        f".{_REFERENCE_SWATCH}{{border-top-style:dashed;border-top-color:#000}}"
        f".{_FROZEN_SWATCH}{{border-top-style:dashed;"
        f"border-top-color:{controller_style(ORACLE_FROZEN).color}}}"
    )


_REFERENCE_SWATCHES = {ORACLE: _REFERENCE_SWATCH, ORACLE_FROZEN: _FROZEN_SWATCH}


def _legend_swatch(name: str) -> str:
    """The swatch class of a legend entry: the oracle's or the frozen optimum's reference
    line, else the controller's."""
    return _REFERENCE_SWATCHES.get(name) or swatch_class(name)[0]


def _legend_html(legends: list[tuple[str, list[tuple[str, str]]]]) -> str:
    """A scenario figure's legends as text: one block per panel column, each episode's line
    swatch and label."""
    blocks = []
    for title, entries in legends:
        items = "".join(
            f'<li><span class="{_legend_swatch(name)}"></span>{esc(label)}</li>'
            for name, label in entries
        )
        blocks.append(f"<div><b>{esc(title)}</b><ul>{items}</ul></div>")
    return f'<div class="legend">{"".join(blocks)}</div>'


def _figure(stem: str, fig: _Embedded, caption: str) -> str:
    legend = _legend_html(fig.legends) if fig.legends else ""
    image = f'<img src="{fig.uri}" alt="{esc(caption)}" loading="lazy">'
    if fig.size is not None:  # a file beside the page, its legends (drawn below) hidden
        width, height = fig.size
        image = (
            f'<div class="crop" style="aspect-ratio:{width}/{max(1, round(height * fig.shown))};'
            f'max-width:{width}px">{image}</div>'
        )
    return (
        f'<figure id="fig-{esc(stem)}">{image}'
        f"{legend}<figcaption>{esc(caption)} — <code>{esc(fig.file)}</code></figcaption></figure>"
    )


def figure_sections(
    figures: Iterable[str | Path], scenarios: Iterable[str] = (), folder: str | Path | None = None
) -> tuple[str, str, list[str]]:
    """(ranking figures, scenario figures, the controllers their legends name) as HTML: per
    split its interval estimates, then its performance profiles; the scenario figures in
    the order of ``figures``, captioned with the scenario's name where ``scenarios`` has
    it.  ``folder``: the page's; the scenario figures are then linked as the files beside
    it (:data:`LINKED_KINDS`), else every figure is embedded."""
    names = {anchor(s): s for s in scenarios}
    ranking: list[tuple[str, int, str]] = []
    drawn = []
    legend_names: list[str] = []
    for stem, fig in embedded_figures(figures, folder).items():
        kind, _, split = stem.partition("_")
        legend_names += [n for _, entries in fig.legends or () for n, _ in entries]
        if stem == LEARNING_CURVES_STEM:  # after the ranking figures of every split
            caption = (
                "learning curves of the learned agents: per training seed, the validation cost "
                "over the oracle's (or the validation return, for an agent without that metric)"
            )
            ranking.append(("~", True, _figure(stem, fig, caption)))
        elif kind in ("ranking", "profile"):
            what = "interval estimates" if kind == "ranking" else "performance profiles"
            ranking.append((split, kind == "profile", _figure(stem, fig, f"{what}, {split}")))
        else:
            label = names.get(stem, stem.removeprefix("scenario_"))
            drawn.append(_figure(stem, fig, f"scenario {label}"))
    ranking_html = "".join(h for *_, h in sorted(ranking, key=lambda r: r[:2]))
    return ranking_html, "".join(drawn), legend_names

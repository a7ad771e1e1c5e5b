"""Writing a figure: the page's palette PNG (at most :data:`PAGE_WIDTH` pixels, its text
chunks) and the vector copy (SVG, or SVGZ for the long trajectories), reproducibly; the
figures themselves: :mod:`.figures`."""

from __future__ import annotations

import gzip
import io
import math
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from shipgym_baselines.plots.style import FIGURE_DPI
from shipgym_baselines.records.outfiles import write_bytes

#: the figures' files: text kept as text in the SVG, a fixed hash salt (reproducible ids),
#: and lines simplified to 0.5 px (matplotlib drops a vertex that moves its line by less
#: than this fraction of a pixel; default 1/9): lighter files that look the same
LIGHT_FIGURES = {
    "svg.fonttype": "none",
    "svg.hashsalt": "shipgym",
    "path.simplify": True,
    "path.simplify_threshold": 0.5,
}
#: widest PNG [px]: a figure drawn at FIGURE_DPI is written at 1/2, 1/3, … of its pixels,
#: the first that fits (a 200-dpi figure at 100 dpi or less: the page shows no more; the
#: vector copy keeps every detail; fewer pixels barely lighten a line figure: its
#: compressed bytes follow the lines' length in pixels, not the area)
PAGE_WIDTH = 1400
#: a scenario figure's PNG text chunks for the page: its legends as JSON (a list
#: of [column title, [[controller, label], …]]; the oracle's label ends ", the reference",
#: the frozen optimum's ", never adapts")
#: and where they start (the fraction of the height from the top); the page shows the
#: image above that line and the legends as text (crisp at any zoom, and ≈ 15 % of the
#: image's bytes)
LEGEND_KEY = "shipgym:legend"
LEGEND_TOP_KEY = "shipgym:legend-top"
#: most colours of a page PNG's palette: the figure's own colours (every line, marker, text
#: and patch, an alpha one as it shows on white), each also half-way to white (the
#: antialiasing of a thin line on the white axes), and a ramp of PAGE_GREYS greys (text,
#: grid); every pixel takes its nearest (so a controller keeps its colour on the
#: page; an adaptive 64-colour palette spent itself on near-whites and greyed the lines)
PAGE_COLOURS = 256
PAGE_GREYS = 9


def pyplot() -> Any:
    """``matplotlib.pyplot`` on the non-interactive Agg backend."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def figure_stem(name: str) -> str:
    """A file-name stem for a scenario or split: ``heldout:0`` → ``heldout_0``, a YAML path →
    its stem."""
    if name.endswith((".yaml", ".yml")) or "/" in name:
        name = Path(name).stem
    return "".join(c if c.isalnum() or c in "-_." else "_" for c in name)


def save_figure(
    fig: Any,
    out_dir: str | Path,
    stem: str,
    tight: bool = False,
    vector: str | None = None,
    page_text: Mapping[str, str] | None = None,
) -> list[Path]:
    """Write ``fig`` as ``<stem>.png`` (the page's image, :func:`write_page_png`) and, if
    asked, its vector copy ``<stem><vector>`` (``.svg``, or ``.svgz``: the SVG deflated, for
    a figure of long trajectories; None: none, the default of a run: the page
    shows the PNG and the copy would double the figures' weight) into ``out_dir`` (made if
    missing), close it and return the paths.  ``tight``: crop to what is drawn (for a
    figure drawn outside its canvas, as rliable's interval plot is); a layout engine's
    layout is computed once (the PNG) and kept for the SVG.  ``page_text``: text chunks
    of the PNG for the page (:data:`LEGEND_KEY`, :data:`LEGEND_TOP_KEY`)."""
    from PIL import Image

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = [out / f"{stem}.png"] + ([out / f"{stem}{vector}"] if vector else [])
    bbox = "tight" if tight else None
    with pyplot().rc_context(LIGHT_FIGURES):
        if tight:  # the crop is savefig's: through a PNG
            png = io.BytesIO()
            fig.savefig(png, format="png", dpi=FIGURE_DPI, bbox_inches=bbox)
            with Image.open(png) as image:
                rgb = image.convert("RGB")
        else:  # the canvas's pixels as drawn (no PNG written and read back)
            fig.set_dpi(FIGURE_DPI)
            fig.canvas.draw()
            rgb = Image.fromarray(np.asarray(fig.canvas.buffer_rgba())[..., :3])
        write_page_png(rgb, paths[0], page_text, figure_colours(fig))
        if not vector:
            pyplot().close(fig)
            return paths
        fig.set_layout_engine("none")
        svg = io.BytesIO()
        fig.savefig(svg, format="svg", bbox_inches=bbox, metadata={"Date": None})
    if vector == ".svgz":  # mtime 0: the same figure gives the same bytes
        write_bytes(paths[1], gzip.compress(svg.getvalue(), compresslevel=9, mtime=0))
    else:
        write_bytes(paths[1], svg.getvalue())
    pyplot().close(fig)
    return paths


def figure_colours(fig: Any) -> set[tuple[float, float, float]]:
    """The RGB colours [0, 1] that ``fig``'s artists draw with (lines, markers, text,
    patches, collections), an alpha colour as it shows on white."""
    from matplotlib.collections import Collection
    from matplotlib.colors import to_rgba, to_rgba_array
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch
    from matplotlib.text import Text

    rgba: list[Any] = []
    for artist in fig.findobj():
        if isinstance(artist, Line2D):
            rgba.append(to_rgba(artist.get_color(), artist.get_alpha()))
            for marker in (artist.get_markerfacecolor(), artist.get_markeredgecolor()):
                if not (isinstance(marker, str) and marker == "none"):
                    rgba.append(to_rgba(marker, artist.get_alpha()))
        elif isinstance(artist, Text) and artist.get_text():
            rgba.append(to_rgba(artist.get_color(), artist.get_alpha()))
        elif isinstance(artist, Patch | Collection):
            faces = [artist.get_facecolor(), artist.get_edgecolor()]
            for colours in faces:
                rgba += list(to_rgba_array(colours))
    colours = set()
    for r, g, b, a in rgba:
        if a > 0.0:
            colours.add(tuple(float(v) * a + (1.0 - a) for v in (r, g, b)))
    return colours


def page_palette(colours: Iterable[tuple[float, float, float]]) -> list[tuple[int, int, int]]:
    """The page PNG's palette (:data:`PAGE_COLOURS`, 8-bit RGB): the grey ramp, then
    ``colours``, each also half-way to white; the first :data:`PAGE_COLOURS` distinct
    ones."""
    greys = [(g, g, g) for g in np.linspace(0.0, 1.0, PAGE_GREYS).tolist()]
    palette = []
    for c in [*greys, *sorted(colours)]:
        for t in (0.0, 0.5):
            palette.append(tuple(round(255.0 * (v * (1.0 - t) + t)) for v in c))
    return list(dict.fromkeys(palette))[:PAGE_COLOURS]


def write_page_png(
    rgb: Any,
    path: Path,
    text: Mapping[str, str] | None = None,
    colours: Iterable[tuple[float, float, float]] = (),
) -> None:
    """``rgb`` (a PIL RGB image of the figure drawn at :data:`FIGURE_DPI`) written as the
    page shows it (kept light: the page embeds it): reduced by the smallest whole factor that
    makes it at most :data:`PAGE_WIDTH` pixels wide (each pixel the mean of its block; the
    dpi recorded accordingly), each pixel the nearest colour of :func:`page_palette` of
    the figure's ``colours`` (:func:`figure_colours`; no dithering), deflated at the
    highest level; ``text``: its text chunks (key → value)."""
    from PIL import Image, PngImagePlugin

    info = PngImagePlugin.PngInfo()
    for key, value in (text or {}).items():
        info.add_itxt(key, value)
    factor = math.ceil(rgb.width / PAGE_WIDTH)
    if factor > 1:
        rgb = rgb.reduce(factor)
    entries = page_palette(colours)
    flat = [v for c in entries for v in c]
    palette_image = Image.new("P", (1, 1))
    palette_image.putpalette(flat + flat[:3] * (256 - len(entries)))
    indexed = rgb.quantize(palette=palette_image, dither=Image.Dither.NONE)
    page = io.BytesIO()
    indexed.save(page, format="PNG", optimize=True, dpi=(FIGURE_DPI / factor,) * 2, pnginfo=info)
    write_bytes(path, page.getvalue())

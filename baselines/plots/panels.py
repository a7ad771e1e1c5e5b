"""What the figures share: the panel columns by controller family, the axes at fixed
positions with the legends below, the references' line styles and the log cost-ratio
axis."""

from __future__ import annotations

import functools
import math
from collections import defaultdict
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

from shipgym_baselines.escaping import plain_text
from shipgym_baselines.plots.style import controller_style
from shipgym_baselines.policy import FAMILIES
from shipgym_baselines.privileged import ORACLE_FROZEN
from shipgym_baselines.registry import declared_traits
from shipgym_baselines.scoring.scores import REFERENCE_KIND

#: most controllers drawn in one panel; a bigger family is split over several columns
PANEL_CONTROLLERS = 5


#: the oracle's episode, drawn in every column as the reference
ORACLE_STYLE = {"color": "black", "linestyle": (0, (4, 1.5)), "alpha": 0.75, "zorder": 1.5}


@functools.cache
def frozen_style() -> dict[str, Any]:
    """The frozen optimum's episode (``oracle_frozen``: the oracle's truth frozen at the
    start), drawn in every column beside the oracle's: its registered colour (read when
    first drawn, so importing the figures loads no controller), dash-dotted."""
    return {
        "color": controller_style(ORACLE_FROZEN).color,
        "linestyle": (0, (5, 1.5, 1, 1.5)),
        "alpha": 0.85,
        "zorder": 1.4,
    }


def controller_family(name: str, kind: str | None = None) -> str:
    """The controller's family (one of :data:`FAMILIES`): the column it is drawn in.

    The family its registration declares (a shipped learned agent's: ``learned``,
    :func:`shipgym_baselines.registry.declared_traits`); for a name nothing declares one
    for (a plug-in, a renamed long form, a trained agent's folder), its ``kind``'s
    (``learned``; ``reference``: ``references``), else the family its name reads as,
    else ``other``."""
    family, _ = declared_traits(name)
    if family is not None:
        return family
    if kind == "learned":
        return "learned"
    if kind == REFERENCE_KIND:
        return "references"
    if name.startswith("pid"):
        return "PID"
    if name.endswith("lqr"):
        return "LQR"
    if name.startswith("nmpc"):
        return "NMPC"
    if "backstepping" in name:
        return "backstepping"
    return "other"


def family_panels(
    controllers: Iterable[str], kinds: Mapping[str, str] | None = None
) -> list[tuple[str, list[str]]]:
    """(title, controllers) of each panel column: families in :data:`FAMILIES` order, each
    split into chunks of at most :data:`PANEL_CONTROLLERS`, controllers in given order."""
    groups: dict[str, list[str]] = defaultdict(list)
    for name in controllers:
        groups[controller_family(name, (kinds or {}).get(name))].append(name)
    panels = []
    for family in FAMILIES:
        members = groups.get(family, [])
        chunks = [
            members[i : i + PANEL_CONTROLLERS] for i in range(0, len(members), PANEL_CONTROLLERS)
        ]
        for k, chunk in enumerate(chunks):
            title = family if len(chunks) == 1 else f"{family} ({k + 1}/{len(chunks)})"
            panels.append((title, chunk))
    return panels


#: layout of a scenario figure [in]: panel width, row heights (track, e, δ), margins, the gap
#: between columns, between rows, the legends' room and the extra room of an own-scale column
PANEL_W, ROWS_H = 2.4, (2.1, 1.6, 1.6)
LEFT, RIGHT, TOP, GAP, ROW_GAP, OWN_GAP = 0.8, 0.15, 0.65, 0.2, 0.5, 0.55
LEGEND_LINE = 0.14  # [in] a legend entry


def column_axes(
    fig: Any, rows_h: Sequence[float], own_scale: Sequence[bool], legend_lines: int
) -> list[list[Any]]:
    """One axes per row (heights ``rows_h`` [in]) in each of ``len(own_scale)`` columns, at
    fixed positions (no layout engine: fast, the same in every figure, and room for the
    legends below, :func:`legend_below`); a column with its own scale gets room for its
    tick labels."""
    n = len(own_scale)
    width = LEFT + n * PANEL_W + (n - 1) * GAP + OWN_GAP * sum(own_scale[1:]) + RIGHT
    height = TOP + sum(rows_h) + len(rows_h) * ROW_GAP + legend_lines * LEGEND_LINE + 0.15
    fig.set_size_inches(width, height)
    columns, left = [], LEFT
    for col in range(n):
        if col and own_scale[col]:
            left += OWN_GAP
        top, axes = height - TOP, []
        for h in rows_h:
            top -= h
            axes.append(fig.add_axes((left / width, top / height, PANEL_W / width, h / height)))
            top -= ROW_GAP
        columns.append(axes)
        left += PANEL_W + GAP
    return columns


def legend_below(ax: Any, handles: Sequence[Any] | None = None) -> None:
    """The legend of a column under its bottom axes ``ax``, outside the data (in the room
    :func:`column_axes` leaves)."""
    height = ax.get_position().height * ax.figure.get_figheight()
    if handles is None:
        handles, labels = ax.get_legend_handles_labels()
    else:
        labels = [h.get_label() for h in handles]
    ax.legend(
        handles,
        [plain_text(label) for label in labels],  # names drawn as typed
        loc="upper center",
        bbox_to_anchor=(0.5, -ROW_GAP / height - 0.02),
        fontsize=6.5,
        frameon=False,
        borderaxespad=0.0,
    )


def log_ratio_axis(ax: Any, values: Iterable[float], axis: str = "x") -> None:
    """A log ``axis`` ("x" or "y") over the finite positive ``values`` and 1 (the oracle),
    with plain number labels."""
    from matplotlib.ticker import LogLocator, NullFormatter, ScalarFormatter

    finite = [v for v in values if math.isfinite(v) and v > 0] + [1.0]
    low, high = min(finite), max(finite)
    getattr(ax, f"set_{axis}scale")("log")
    getattr(ax, f"set_{axis}lim")(low / 1.15, high * 1.15)
    scale = getattr(ax, f"{axis}axis")
    scale.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    formatter = ScalarFormatter()
    formatter.set_scientific(False)
    scale.set_major_formatter(formatter)
    scale.set_minor_formatter(NullFormatter())

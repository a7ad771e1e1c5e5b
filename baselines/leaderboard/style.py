"""One look per controller in every figure: a fixed colour, line style and marker.

The built-in controllers and shipped agents get fixed entries (families share a hue
family: PID blues, LQR greens, NMPC oranges, backstepping purples, learned agents reds and
browns, references greys); any other name (a plug-in, a trained agent's folder) gets a
stable entry derived from its name (CRC-32, so the same in every run and process).
"""

from __future__ import annotations

import zlib
from dataclasses import dataclass


@dataclass(frozen=True)
class Style:
    """Matplotlib keyword arguments of one controller."""

    color: str
    linestyle: str
    marker: str

    def kwargs(self) -> dict[str, str]:
        return {"color": self.color, "linestyle": self.linestyle}


_FIXED: dict[str, Style] = {
    "pid_los": Style("#1f77b4", "-", "o"),
    "pid_lookahead_los": Style("#6baed6", "--", "o"),
    "pid_vf": Style("#08519c", "-.", "o"),
    "pid_tvvf": Style("#9ecae1", ":", "o"),
    "lqr": Style("#31a354", "-", "s"),
    "adaptive_lqr": Style("#74c476", "--", "s"),
    "nmpc": Style("#fd8d3c", "-", "^"),
    "nmpc_wlssvm": Style("#e6550d", "--", "^"),
    "nmpc_lambda_lssvm": Style("#a63603", "-.", "^"),
    "nmpc_wlssvm_svf": Style("#fdae6b", ":", "^"),
    "nmpc_lambda_lssvm_svf": Style("#7f2704", ":", "v"),
    "l1_backstepping": Style("#756bb1", "-", "D"),
    "adaptive_backstepping": Style("#bcbddc", "--", "D"),
    "ppo": Style("#d62728", "-", "P"),
    "ppo_guidance": Style("#ff9896", "--", "P"),
    "recurrent_ppo": Style("#8c564b", "-", "X"),
    "sac": Style("#e377c2", "-.", "*"),
    "td3": Style("#c49c94", ":", "*"),
    "ppo_history": Style("#ad494a", "--", "P"),
    "dagger": Style("#67000d", "-", "h"),
    "bc": Style("#e7969c", ":", "h"),
    "zero_rudder": Style("#7f7f7f", ":", "."),
    "random": Style("#c7c7c7", ":", "."),
    "oracle_frozen": Style("#525252", "-.", "x"),
}

_PALETTE = (
    "#17becf", "#bcbd22", "#9467bd", "#2ca02c", "#ff7f0e", "#e7298a", "#66a61e", "#a6761d",
    "#1b9e77", "#d95f02", "#7570b3", "#e6ab02",
)  # fmt: skip
_LINESTYLES = ("-", "--", "-.", ":")
_MARKERS = ("o", "s", "^", "D", "v", "P", "X", "*")


def controller_style(name: str) -> Style:
    """The controller's style in every figure (module doc)."""
    fixed = _FIXED.get(name)
    if fixed is not None:
        return fixed
    h = zlib.crc32(name.encode())
    return Style(
        _PALETTE[h % len(_PALETTE)],
        _LINESTYLES[(h // len(_PALETTE)) % len(_LINESTYLES)],
        _MARKERS[(h // 97) % len(_MARKERS)],
    )


#: resolution of the PNG figures (a vector copy, SVG, is written beside each)
FIGURE_DPI = 200

"""One look per controller in every figure: a fixed colour, line style and marker.

A controller's look is a trait of its registration (``register_controller(..., look=...)``;
a shipped learned agent's: :data:`shipgym_baselines.learned.policy.AGENT_LOOKS`): families
share a hue family (PID blues, LQR greens, NMPC oranges, backstepping purples, learned
agents reds and browns, references greys).  Any other name (a plug-in, a trained agent's
folder) gets a stable look derived from its name (CRC-32, so the same in every run and
process).
"""

from __future__ import annotations

import zlib

from shipgym_baselines.policy import Style
from shipgym_baselines.registry import declared_traits

_PALETTE = (
    "#17becf", "#bcbd22", "#9467bd", "#2ca02c", "#ff7f0e", "#e7298a", "#66a61e", "#a6761d",
    "#1b9e77", "#d95f02", "#7570b3", "#e6ab02",
)  # fmt: skip
_LINESTYLES = ("-", "--", "-.", ":")
_MARKERS = ("o", "s", "^", "D", "v", "P", "X", "*")


def controller_style(name: str) -> Style:
    """The controller's style in every figure (module doc)."""
    _, look = declared_traits(name)
    if look is not None:
        return look
    h = zlib.crc32(name.encode())
    return Style(
        _PALETTE[h % len(_PALETTE)],
        _LINESTYLES[(h // len(_PALETTE)) % len(_LINESTYLES)],
        _MARKERS[(h // 97) % len(_MARKERS)],
    )


#: resolution of the PNG figures (a vector copy, SVG, is written beside each)
FIGURE_DPI = 200

"""What the learned estimator reads: one row of features per control step, a window of rows.

Every entry comes from what every controller receives: the step's ``info`` (measured
position, heading, yaw rate, rudder angle, the applied command) and the controller context
(the nominal model's numbers), scaled by the ship's own numbers so that one network serves
every ship (L, U0, Ts, δmax):

====  ==============================================================================
 0    r·L/U0: the measured yaw rate
 1    δ/δmax: the rudder angle
 2    δc/δmax: the command applied over the period just ended
 3    (δ − δ_prev)/δmax: the rudder's travel over the period (the servo's speed)
 4    Δψ·L/(U0·Ts): the heading's change over the period (wrapped)
 5    surge over ground: the period's displacement along the heading at its start / (U0·Ts)
 6    sway over ground: across it / (U0·Ts) (drift and current)
 7    sin ψ, 8 cos ψ: the heading in the earth frame (an earth-fixed current's direction)
====  ==============================================================================

A reset row (no period yet) has zeros in 3–6.  The window is the last ``WINDOW`` rows,
oldest first, zeros before the episode's start, followed by the controller context's
``feature_row`` (:data:`shipgym.envs.core.CONTEXT_NAMES`: the nominal model's Nomoto K and
T, L, U0, Ts, δmax, scaled as the env scales them).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from shipgym.angles import wrap_angle
from shipgym.envs.context import ControllerContext

#: the features of one control step (module doc)
STEP_FEATURES = (
    "yaw_rate",
    "rudder",
    "command",
    "rudder_travel",
    "heading_change",
    "surge_over_ground",
    "sway_over_ground",
    "sin_heading",
    "cos_heading",
)
#: control steps in a window
WINDOW = 32


def step_row(
    info: Mapping[str, Any], previous: Mapping[str, Any] | None, ctx: ControllerContext
) -> np.ndarray:
    """The features of one step (module doc) from its ``info`` and the previous step's."""
    length, speed, ts, limit = (
        ctx.ship_length,
        ctx.nominal_speed,
        ctx.control_period,
        (ctx.rudder_limit),
    )
    psi = float(info["heading"])
    row = np.zeros(len(STEP_FEATURES))
    row[0] = float(info["yaw_rate"]) * length / speed
    row[1] = float(info["rudder_angle"]) / limit
    row[2] = float(info["rudder_command"]) / limit
    row[7], row[8] = math.sin(psi), math.cos(psi)
    if previous is not None:
        psi0 = float(previous["heading"])
        row[3] = (float(info["rudder_angle"]) - float(previous["rudder_angle"])) / limit
        row[4] = wrap_angle(psi - psi0) * length / (speed * ts)
        dx = float(info["position"][0]) - float(previous["position"][0])
        dy = float(info["position"][1]) - float(previous["position"][1])
        c, s = math.cos(psi0), math.sin(psi0)
        row[5] = (dx * c + dy * s) / (speed * ts)
        row[6] = (-dx * s + dy * c) / (speed * ts)
    return row


class Window:
    """The last :data:`WINDOW` step rows of an episode, oldest first (zeros before its
    start), and the input of the network (:meth:`input`)."""

    def __init__(self, ctx: ControllerContext) -> None:
        self.ctx = ctx
        self.rows = np.zeros((WINDOW, len(STEP_FEATURES)))
        self._previous: Mapping[str, Any] | None = None

    def add(self, info: Mapping[str, Any]) -> np.ndarray:
        """Append the row of ``info`` (this step's) and return it."""
        row = step_row(info, self._previous, self.ctx)
        self.rows = np.roll(self.rows, -1, axis=0)
        self.rows[-1] = row
        self._previous = {k: info[k] for k in ("heading", "rudder_angle", "position")}
        return row

    def input(self) -> np.ndarray:
        """The network's input: the window's rows, flattened, then the context row."""
        return window_input(self.rows, self.ctx.feature_row)


def window_input(rows: np.ndarray, context: np.ndarray) -> np.ndarray:
    """(…, WINDOW·F + C) the network's input of windows ``rows`` (…, WINDOW, F) and the
    context row(s) ``context`` (…, C)."""
    flat = rows.reshape(*rows.shape[:-2], -1)
    context = np.broadcast_to(context, (*flat.shape[:-1], context.shape[-1]))
    return np.concatenate([flat, context], axis=-1).astype(np.float32)


def episode_windows(rows: np.ndarray, context: np.ndarray) -> np.ndarray:
    """(T, WINDOW·F + C) every step's window input of an episode's rows (T, F): the rows
    before the start as zeros (as :class:`Window` holds them)."""
    padded = np.concatenate([np.zeros((WINDOW - 1, rows.shape[1])), rows])
    index = np.arange(rows.shape[0])[:, None] + np.arange(WINDOW)[None, :]
    return window_input(padded[index], context)

"""What the learned estimator estimates: one vector of slots for every ship, and its labels.

The slots are the adapted quantities of every ship (:mod:`shipgym.identification.adaptation`,
ln factors on the nominal ship) and the disturbances, each in its own scale:

=============  ==========================================================
``servo`` …    ln factor of each adapted quantity (a ship has some of them:
``time``       :data:`SLOTS`; the others are masked out of its loss)
``current_x``  the current's earth-frame components / U0
``current_y``
``bias``       the yaw bias / the bias equivalent to full rudder
               (:func:`shipgym.identification.ekf.full_rudder_bias`)
=============  ==========================================================

A label is read from the truth at training time only (the teacher channel,
:func:`shipgym_baselines.privileged.teacher_truth`): the quantities by least squares of the
adaptation map onto the true parameter vector (exact where the change is one of the map's,
as every change of the training distribution is), the current as it acts now less the waves,
the yaw bias as the model's ``yaw_disturbance`` plus, on nomoto2, the shift of d0 (which
enters its yaw equation as the bias does).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import least_squares

from shipgym.envs.context import ControllerContext
from shipgym.envs.truth import PlantTruth
from shipgym.identification.adaptation import QUANTITIES, Adaptation
from shipgym.identification.ekf import full_rudder_bias

#: the adapted quantities of any ship, in slot order
QUANTITY_SLOTS = ("servo", "rate", "rudder", "draught", "gain", "time")
#: every slot (module doc)
SLOTS = (*QUANTITY_SLOTS, "current_x", "current_y", "bias")
#: the slots φ does not estimate: the training distribution never moves a rate limit
#: (its rudder aging slows the servo's time constant only), so φ would learn a constant 0
#: with full confidence; the controller takes them from the servo's fit
UNLEARNED = ("rate",)


def slot_mask(ship: str, learned: bool = False) -> np.ndarray:
    """(len(SLOTS),) 1 where ``ship`` has the slot, else 0; ``learned``: only where φ
    estimates it (not :data:`UNLEARNED`: the loss's mask)."""
    names = {q.name for q in QUANTITIES[ship]}
    return np.array(
        [
            1.0
            if (s in names or s not in QUANTITY_SLOTS) and not (learned and s in UNLEARNED)
            else 0.0
            for s in SLOTS
        ]
    )


class Labeller:
    """The labels of one ship's truths (module doc); the quantities' fits cached per true
    parameter vector."""

    def __init__(self, ctx: ControllerContext) -> None:
        self.ctx = ctx
        self.adaptation = Adaptation(ctx.ship, ctx.nominal_params)
        model = ctx.nominal_model
        self.bias_scale = full_rudder_bias(model, ctx.rudder_limit)
        self.i_bias = model.disturbance_names.index("yaw_disturbance")
        names = type(ctx.nominal_params).names()
        self.i_d0 = names.index("d0") if "d0" in names else None
        self.nominal = ctx.nominal_params.to_vector()
        self._fits: dict[bytes, np.ndarray] = {}

    def quantities(self, theta: np.ndarray) -> np.ndarray:
        """η of the ship's quantities that best gives ``theta`` (least squares in ln |θ|)."""
        key = theta.tobytes()
        if key not in self._fits:
            used = self.nominal != 0.0
            target = np.log(np.abs(theta[used]))

            def residual(eta: np.ndarray) -> np.ndarray:
                return np.log(np.abs(self.adaptation.params(eta)[used])) - target

            a = self.adaptation
            start = np.zeros(a.size)
            if np.allclose(theta, self.nominal, rtol=1e-12, atol=0.0):
                self._fits[key] = start
            else:
                fit = least_squares(residual, start, bounds=(a.low, a.high))
                self._fits[key] = fit.x
        return self._fits[key]

    def __call__(self, truth: PlantTruth) -> np.ndarray:
        """(len(SLOTS),) the labels of ``truth`` (zeros in the slots the ship lacks)."""
        out = np.zeros(len(SLOTS))
        theta = truth.params.to_vector()
        for name, value in zip(self.adaptation.names, self.quantities(theta), strict=True):
            out[SLOTS.index(name)] = value
        w = truth.without_waves
        speed = self.ctx.nominal_speed
        out[SLOTS.index("current_x")] = w[0] / speed
        out[SLOTS.index("current_y")] = w[1] / speed
        bias = w[self.i_bias]
        if self.i_d0 is not None:
            bias += theta[self.i_d0] - self.nominal[self.i_d0]
        out[SLOTS.index("bias")] = bias / self.bias_scale
        return out


def plant_of(
    ctx: ControllerContext, adaptation: Adaptation, slots: np.ndarray, bias_scale: float
) -> tuple[np.ndarray, np.ndarray]:
    """(parameter vector, disturbances) of an estimate in slots, through ``ctx``'s ship's
    ``adaptation`` map (the inverse of the labels: nomoto2's bias goes to its
    yaw_disturbance)."""
    eta = np.array([slots[SLOTS.index(n)] for n in adaptation.names])
    theta = adaptation.params(adaptation.clip(eta))
    model = ctx.nominal_model
    w = np.zeros(model.n_disturbances)
    speed = ctx.nominal_speed
    w[0] = slots[SLOTS.index("current_x")] * speed
    w[1] = slots[SLOTS.index("current_y")] * speed
    w[model.disturbance_names.index("yaw_disturbance")] = slots[SLOTS.index("bias")] * bias_scale
    if not all(map(math.isfinite, w)):
        w[:] = 0.0
    return theta, w

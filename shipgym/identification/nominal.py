"""The nominal Nomoto models of a ship, for model-based controller design.

A model with a closed form (:meth:`ShipModel.closed_form_nomoto`, e.g. nomoto2) gives its
own parameters; every other ship gets the fit to its own 20/20 zig-zag
(:func:`shipgym.identification.zigzag.ship_nomoto`, Xu & Guedes Soares 2020 §5.2, cached
per process): computed from the model's simulation, never typed in.
"""

from __future__ import annotations

from shipgym.identification.zigzag import ship_nomoto
from shipgym.models.base import ParameterRecord, ShipModel
from shipgym.models.nomoto2 import nomoto2_first_order


def second_order_nomoto(
    model: ShipModel, params: ParameterRecord | None = None
) -> tuple[float, float, float, float]:
    """2nd-order Nomoto (K [1/s], T1, T2, T3 [s]) of ``model`` (with ``params`` if given)."""
    model = model if params is None else model.with_params(params)
    closed_form = model.closed_form_nomoto()
    if closed_form is not None:
        return closed_form
    fit, _ = ship_nomoto(model)
    return fit.K, fit.T1, fit.T2, fit.T3


def first_order_nomoto(
    model: ShipModel, params: ParameterRecord | None = None
) -> tuple[float, float]:
    """First-order Nomoto (K [1/s], T [s]) of ``model`` (with ``params`` if given).

    Nomoto's approximation T = T1 + T2 − T3 of :func:`second_order_nomoto`.
    """
    return nomoto2_first_order(*second_order_nomoto(model, params))

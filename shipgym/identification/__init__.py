"""Identification toolkit: LS-SVM, λ-LS-SVM online, continuous LS, zig-zag fits.

Public entry points: :func:`fit_nomoto2` (batch, Liu et al. 2019) and :class:`LambdaLSSVM`
(online, Algorithm 2), fed with ``info["samples"]`` of the env, both with
``front_end="differences"`` (the paper's) or ``"svf"`` (outlier + state-variable filter);
:func:`first_order_nomoto` and :func:`second_order_nomoto`, a ship's nominal model for
controller design.
"""

from shipgym.identification.blanke import BlankeFit, fit_blanke
from shipgym.identification.continuous_ls import ContinuousLeastSquares
from shipgym.identification.front_end import (
    FrontEndSettings,
    HampelFilter,
    StateVariableFilter,
)
from shipgym.identification.lssvm import (
    LSSVMSolution,
    lssvm_dual,
    lssvm_primal,
    robust_scale,
    robust_weights,
    weighted_lssvm,
)
from shipgym.identification.nominal import first_order_nomoto, second_order_nomoto
from shipgym.identification.nomoto import (
    IdentificationError,
    fit_nomoto2,
    forward_difference,
    nomoto_regressors,
    params_from_theta1,
    regression_rows,
    theta1_from_params,
)
from shipgym.identification.online import LambdaLSSVM, PersistentExcitation, WeightedLSSVMOnline
from shipgym.identification.zigzag import NomotoFit, fit_nomoto_zigzag, zigzag_nomoto

__all__ = [
    "BlankeFit",
    "ContinuousLeastSquares",
    "FrontEndSettings",
    "HampelFilter",
    "IdentificationError",
    "LSSVMSolution",
    "LambdaLSSVM",
    "NomotoFit",
    "PersistentExcitation",
    "StateVariableFilter",
    "WeightedLSSVMOnline",
    "first_order_nomoto",
    "fit_blanke",
    "fit_nomoto2",
    "fit_nomoto_zigzag",
    "forward_difference",
    "lssvm_dual",
    "lssvm_primal",
    "nomoto_regressors",
    "params_from_theta1",
    "regression_rows",
    "robust_scale",
    "robust_weights",
    "second_order_nomoto",
    "theta1_from_params",
    "weighted_lssvm",
    "zigzag_nomoto",
]

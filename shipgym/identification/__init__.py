"""Identification toolkit: LS-SVM, λ-LS-SVM online, continuous LS, zig-zag fits.

Public entry points: :func:`~shipgym.identification.nomoto.fit_nomoto2` (batch, Liu et al. 2019)
and :class:`~shipgym.identification.online.LambdaLSSVM`
(online, Algorithm 2), fed with ``info["samples"]`` of the env, both with
``front_end="differences"`` (the paper's) or ``"svf"`` (outlier + state-variable filter);
:func:`~shipgym.identification.nominal.first_order_nomoto` and
:func:`~shipgym.identification.nominal.second_order_nomoto`, a ship's nominal model for
controller design.
"""

"""Identification misuse is named, never a wrong model: a NaN names
its array and index, arrays of different lengths name the arrays, a log too short for the
model's time constants names the minimum length."""

from __future__ import annotations

import numpy as np
import pytest

from shipgym.identification.errors import IdentificationError, minimum_samples
from shipgym.identification.nomoto import fit_nomoto2
from shipgym.identification.online import LambdaLSSVM
from shipgym.models.nomoto2 import Nomoto2Params
from tests.shipgym.identification.logs import H, simulate


@pytest.fixture(scope="module")
def log() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return simulate(Nomoto2Params(), duration=30.0)


@pytest.mark.parametrize("front_end", ["differences", "svf"])
def test_finding10_a_nan_names_the_array_and_index(log, front_end: str) -> None:
    psi, delta, delta_c = (a.copy() for a in log)
    delta_c[417] = np.nan
    with pytest.raises(IdentificationError, match=r"delta_c\[417\] = nan"):
        fit_nomoto2(psi, delta, delta_c, H, front_end=front_end)
    psi[12] = np.inf
    with pytest.raises(IdentificationError, match=r"psi\[12\] = inf, delta_c\[417\] = nan"):
        fit_nomoto2(psi, delta, delta_c, H, front_end=front_end)


def test_finding10_a_dropped_online_sample_is_named_in_the_note(log) -> None:
    """Online, a non-finite sample is a dropped one (the difference chain restarts, tested
    in test_identification); the note names where it was."""
    psi, delta, delta_c = (a.copy() for a in log)
    psi[30] = np.nan
    ident = LambdaLSSVM(H)
    ident.update({"psi": psi[:50], "delta": delta[:50], "delta_c": delta_c[:50]})
    assert ident.last_reason is not None and "psi[30] = nan" in ident.last_reason


def test_finding10_arrays_of_different_lengths_name_the_arrays(log) -> None:
    psi, delta, delta_c = log
    said = r"psi, delta and delta_c must have equal lengths; got psi 2000, delta 1999, delta_c"
    with pytest.raises(IdentificationError, match=said):
        fit_nomoto2(psi[:2000], delta[:1999], delta_c[:2000], H)
    ident = LambdaLSSVM(H)
    with pytest.raises(IdentificationError, match=r"got psi 50, delta 50, delta_c 49"):
        ident.update({"psi": psi[:50], "delta": delta[:50], "delta_c": delta_c[:49]})


def test_finding10_a_log_too_short_for_the_time_constants_names_the_minimum(log) -> None:
    """The audit's probe: 30 samples (0.3 s) returned K = 0.0228 against 0.506."""
    psi, delta, delta_c = log
    need = minimum_samples(Nomoto2Params().T1, H)
    assert need == 626  # 5·T1 = 6.24 s at h = 0.01 s
    for start in (0, 1000):
        part = slice(start, start + 30)
        with pytest.raises(IdentificationError, match=rf"30 samples .* at least {need} samples"):
            fit_nomoto2(psi[part], delta[part], delta_c[part], H)
    fit = fit_nomoto2(
        psi[1000 : 1000 + need], delta[1000 : 1000 + need], delta_c[1000 : 1000 + need], H
    )
    assert fit.K == pytest.approx(0.506, rel=0.01)  # at the minimum the model is right
    # a slow identified model needs a longer log than the base model's T1 alone
    slow = Nomoto2Params(T1=0.2, T2=0.1)
    with pytest.raises(IdentificationError, match="too short to identify the identified model"):
        fit_nomoto2(psi[:200], delta[:200], delta_c[:200], H, base=slow)

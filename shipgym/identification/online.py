"""Online identification of the nomoto2 model: sliding window, weighted and λ-LS-SVM.

Liu et al. (2019) §3.2:

* sliding data window (§3.2.1): regression rows accumulate; the first model is identified
  when the window holds N_w rows, then every time it holds N_w + N_u rows the oldest N_u
  are dropped and the model is re-identified (N_w = 1200, N_u = 50 at h = 0.01 s, i.e. one
  update per 0.5 s control period);
* :class:`WeightedLSSVMOnline`: weighted LS-SVM on each window, nothing else;
* :class:`LambdaLSSVM` (Algorithm 2): the change index λ_k (eq. (43)) of each sub-model,
  computed with the previous model on the newest N_u rows; when λ_k exceeds λ_c the rows of
  the older half of the window are re-weighted by c3 and the newer half by c4 (eq. (44));
  a θ1 giving K < 0 or T1 < 0 (or no real T1, T2) is rejected and the previous one kept;
* :class:`PersistentExcitation`: u_per = u_ori + N(0, σ²) (eq. (45)).

Both identifiers take the front end of the regression as an option: ``front_end=
"differences"`` (the paper's, default) or ``"svf"`` with ``svf_bandwidth`` [rad/s] and the
outlier filter's ``outlier_filter`` / ``outlier_window`` / ``outlier_threshold``
(:mod:`shipgym.identification.front_end`); its filter states are carried across ``update``
calls and window slides, and its look-ahead (``delay`` samples) only delays the rows.

Units of λ_c.  The paper's thresholds λ_c¹ = 1e-5 and λ_c² = 1e-2 only make sense with
angles in degrees: with radians y2 = (δc − δ)·h never exceeds 0.52·0.01 = 5e-3, so λ_k²
could never pass 1e-2.  λ_k is therefore evaluated on errors converted to degrees
(``index_unit="deg"``, default; ``"rad"`` available).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from shipgym.identification.errors import (
    IdentificationError,
    check_sample_keys,
    check_sampling_step,
)
from shipgym.identification.front_end import FrontEndSettings
from shipgym.identification.lssvm import LSSVMSolution
from shipgym.identification.nomoto import (
    excitation_problem,
    front_end_settings,
    params_from_theta1,
    regression_rows,
    solve_theta,
    tc_from_theta2,
    theta1_from_params,
)
from shipgym.models.nomoto2 import Nomoto2Params

RAD_TO_DEG = 180.0 / math.pi
#: Liu et al. (2019) §4: window N_w and update period N_u [samples, at h = 0.01 s], λ_c¹, λ_c²
PAPER_WINDOW = 1200
PAPER_UPDATE_EVERY = 50
PAPER_LAMBDA_C = (1e-5, 1e-2)
#: the keys of ``info["samples"]`` an identifier reads
SAMPLE_KEYS = ("psi", "delta", "delta_c")


class PersistentExcitation:
    """Liu et al. (2019) eq. (45): add i.i.d. N(0, σ²) noise to a control input [rad].

    ``hold``: calls (control periods) each draw is held for (1: a new draw every call, the
    paper's; a slower ship holds it longer, :mod:`shipgym_baselines.classical.nmpc_ship`).
    """

    def __init__(self, sigma: float, rng: np.random.Generator | None = None, hold: int = 1) -> None:
        if sigma < 0:
            raise ValueError(f"sigma must be ≥ 0, got {sigma}")
        if hold < 1:
            raise ValueError(f"hold must be ≥ 1, got {hold}")
        self.sigma = sigma
        self.hold = hold
        self.rng = rng if rng is not None else np.random.default_rng()
        self._calls = 0
        self._noise = 0.0

    def __call__(self, u: float) -> float:
        if not self.sigma:
            return u
        if self._calls % self.hold == 0:
            self._noise = self.sigma * float(self.rng.standard_normal())
        self._calls += 1
        return u + self._noise


class _RowWindow:
    """Rows appended at the end and dropped at the front of one preallocated array: the
    window is a view of it (no copy of the whole window per append); the rows are moved to
    the front only when the array's end is reached.  ``width`` None: one value per row."""

    def __init__(self, width: int | None, capacity: int) -> None:
        self._tail = () if width is None else (width,)
        self._buf = np.empty((capacity, *self._tail))
        self._start = self._end = 0

    def __len__(self) -> int:
        return self._end - self._start

    def view(self) -> np.ndarray:
        """The rows in the window, oldest first (a view: valid until the next append)."""
        return self._buf[self._start : self._end]

    def append(self, rows: np.ndarray) -> None:
        k, n = rows.shape[0], self._end - self._start
        if self._end + k > self._buf.shape[0]:
            if n + k > self._buf.shape[0]:  # more than the array holds: a larger one
                grown = np.empty((2 * (n + k), *self._tail))
                grown[:n] = self.view()
                self._buf = grown
            else:
                self._buf[:n] = self.view().copy()  # to the front (the ranges may overlap)
            self._start, self._end = 0, n
        self._buf[self._end : self._end + k] = rows
        self._end += k

    def drop(self, k: int) -> None:
        """Drop the k oldest rows."""
        self._start += min(k, self._end - self._start)


@dataclasses.dataclass
class _SubModel:
    """θ̂ and bias of one regression (θ1: Nomoto, θ2: servo)."""

    theta: np.ndarray
    bias: float = 0.0


class _SlidingWindowNomoto:
    """Streaming regression rows of eq. (35)–(37) in a sliding window (§3.2.1).

    The rows come from a front end (``front_end="differences"``, the paper's, or ``"svf"``:
    :mod:`shipgym.identification.front_end`), whose state is carried across ``update`` calls
    and window slides.
    """

    def __init__(
        self,
        h: float,
        initial: Nomoto2Params | None = None,
        window: int = PAPER_WINDOW,
        update_every: int = PAPER_UPDATE_EVERY,
        gamma: float | None = None,
        servo_model: str = "forward",
        bias_penalty: bool = True,
        *,
        front_end: str | FrontEndSettings = "differences",
        svf_bandwidth: float | None = None,
        outlier_filter: bool | None = None,
        outlier_window: int | None = None,
        outlier_threshold: float | None = None,
    ) -> None:
        h = check_sampling_step(h)
        if window < 10 or update_every < 1:
            raise IdentificationError(
                f"need window ≥ 10 and update_every ≥ 1; got {window}, {update_every}"
            )
        self.h = h
        self.window = window
        self.update_every = update_every
        self.servo_model = servo_model
        self.bias_penalty = bias_penalty
        self.front_end = front_end_settings(
            front_end, svf_bandwidth, outlier_filter, outlier_window, outlier_threshold
        )
        self._source = self.front_end.make(h)
        self.gamma = self.front_end.gamma if gamma is None else gamma
        self.params = initial if initial is not None else Nomoto2Params()
        self._base = self.params
        self.sub1 = _SubModel(theta1_from_params(self.params))
        self.sub2 = _SubModel(np.array([self._theta2_of(self.params.Tc)]))
        capacity = 4 * (window + update_every)  # rows moved to the front every ~3 windows
        self._windows = (
            _RowWindow(6, capacity),
            _RowWindow(None, capacity),
            _RowWindow(1, capacity),
            _RowWindow(None, capacity),
        )
        self.identified = False
        self._window_full = False
        self.updates = 0
        self.last_reason: str | None = None
        self.history: list[dict[str, Any]] = []
        self.t = 0.0

    def _window_data(self) -> tuple[np.ndarray, ...]:
        """The window's regressors (n, 6) and targets (n,) of eq. (36), then its regressors
        (n, 1) and targets (n,) of eq. (37)."""
        return tuple(window.view() for window in self._windows)

    @property
    def delay(self) -> int:
        """Samples between a sample's arrival and its row entering the window."""
        return self._source.delay

    def _theta2_of(self, tc: float) -> float:
        if self.servo_model == "exact":
            return self.h / (1.0 - math.exp(-self.h / tc))
        return tc

    # -- feeding ----------------------------------------------------------------------
    def update(self, samples: Mapping[str, np.ndarray]) -> bool:
        """Feed ``info["samples"]`` (psi, delta, delta_c; t optional); True if re-identified."""
        check_sample_keys(samples, SAMPLE_KEYS)
        if "t" in samples and len(samples["t"]):
            self.t = float(np.asarray(samples["t"])[-1]) + self.h  # end of the period
        return self.update_arrays(samples["psi"], samples["delta"], samples["delta_c"])

    def update_arrays(self, psi: Any, delta: Any, delta_c: Any) -> bool:
        """Feed fine samples (rad); True if the model was re-identified.

        Rows enter the window in the paper's rhythm (N_w, then N_u at a time) however many
        arrive per call.  With the differences a non-finite (dropped) sample breaks the
        difference chain: rows are only built within unbroken runs of samples.
        """
        signals, note = self._source.push(psi, delta, delta_c)
        if note is not None:
            self.last_reason = note
        if not len(signals):
            return False
        return self._feed_rows(regression_rows(signals, self.h))

    def _feed_rows(self, reg: Any) -> bool:
        updated = False
        pos, n_new = 0, reg.y1.shape[0]
        windows = self._windows
        while pos < n_new:
            n = len(windows[1])
            # rows still needed before the next identification (§3.2.1): N_w the first time,
            # then N_u at a time (also after a skipped, degenerate window)
            full = self.identified or self._window_full
            need = self.window + self.update_every - n if full else self.window - n
            take = max(1, min(need, n_new - pos))
            part = slice(pos, pos + take)
            for window, rows in zip(windows, (reg.x1, reg.y1, reg.x2, reg.y2), strict=True):
                window.append(rows[part])
            pos += take
            n = len(windows[1])
            if not full and n >= self.window:
                self._trim(n - self.window)
                self._window_full = True
            elif full and n >= self.window + self.update_every:
                self._trim(n - self.window)
            else:
                continue
            reason = self._degenerate_window()
            if reason is not None:  # keep the previous model and say why
                self.last_reason = reason
                self._record(skipped=reason)
                continue
            self._identify()
            self.identified = True
            updated = True
        return updated

    def _degenerate_window(self) -> str | None:
        """Why the window cannot identify the model (None when it can)."""
        x1, _, x2, _ = self._window_data()
        return excitation_problem(x1, x2)

    def _trim(self, k: int) -> None:
        for window in self._windows:
            window.drop(k)

    # -- identification ---------------------------------------------------------------
    def _identify(self) -> None:
        raise NotImplementedError

    def _solve(self, x: np.ndarray, y: np.ndarray, prior: np.ndarray | None) -> LSSVMSolution:
        sol, _ = solve_theta(x, y, self.gamma, True, self.bias_penalty, prior_weights=prior)
        return sol

    def _accept(
        self,
        theta1: np.ndarray,
        bias1: float,
        theta2: np.ndarray,
        bias2: float,
        reject_negative: bool,
    ) -> dict[str, Any]:
        """Turn θ̂ into parameters; keep the previous sub-model when it is not usable."""
        flags: dict[str, Any] = {"rejected1": False, "rejected2": False}
        try:
            values = params_from_theta1(theta1)
            if reject_negative and (values["K"] < 0 or values["T1"] < 0):
                raise IdentificationError(f"K = {values['K']:.3g} or T1 = {values['T1']:.3g} < 0")
            candidate = self.params.replace(**values)
            self.sub1 = _SubModel(np.asarray(theta1), bias1)
        except (IdentificationError, ValueError) as exc:
            flags["rejected1"] = True
            self.last_reason = f"θ1 kept: {exc}"
            candidate = self.params
        try:
            tc = tc_from_theta2(float(theta2[0]), self.h, self.servo_model)
            candidate = candidate.replace(Tc=tc)
            self.sub2 = _SubModel(np.asarray(theta2), bias2)
        except (IdentificationError, ValueError) as exc:
            flags["rejected2"] = True
            self.last_reason = f"θ2 kept: {exc}"
        self.params = candidate
        self.updates += 1
        return flags

    def _record(self, **extra: Any) -> None:
        self.history.append({"t": self.t, **self.params.as_dict(), **extra})


class WeightedLSSVMOnline(_SlidingWindowNomoto):
    """Weighted LS-SVM on each sliding window (Liu et al. 2019's comparison method).

    No change index, no re-weighting; a θ̂ without real T1, T2 cannot be turned into
    parameters and keeps the previous model (negative K or T1 are accepted, as in the paper's
    Figure 7 where this method "generated some abnormal values").
    """

    def _identify(self) -> None:
        x1, y1, x2, y2 = self._window_data()
        s1 = self._solve(x1, y1, None)
        s2 = self._solve(x2, y2, None)
        flags = self._accept(s1.theta, s1.bias, s2.theta, s2.bias, reject_negative=False)
        self._record(**flags)


class LambdaLSSVM(_SlidingWindowNomoto):
    """λ-LS-SVM online identifier, Liu et al. (2019) Algorithm 2.

    ``update(info["samples"])`` after every env step; ``params`` is the current
    :class:`Nomoto2Params` (SI).  ``history`` holds, per identification, the parameters,
    λ_k¹, λ_k² and which sub-models were re-weighted or rejected.  ``front_end_options``:
    ``front_end``, ``svf_bandwidth``, ``outlier_filter``, ``outlier_window``,
    ``outlier_threshold`` (module doc).
    """

    def __init__(
        self,
        h: float,
        initial: Nomoto2Params | None = None,
        window: int = PAPER_WINDOW,
        update_every: int = PAPER_UPDATE_EVERY,
        gamma: float | None = None,
        lambda_c1: float = PAPER_LAMBDA_C[0],
        lambda_c2: float = PAPER_LAMBDA_C[1],
        c3: float = 0.01,
        c4: float = 0.99,
        index_unit: str = "deg",
        servo_model: str = "forward",
        bias_penalty: bool = True,
        **front_end_options: Any,
    ) -> None:
        super().__init__(
            h, initial, window, update_every, gamma, servo_model, bias_penalty, **front_end_options
        )
        if index_unit not in ("deg", "rad"):
            raise IdentificationError(f"index_unit must be 'deg' or 'rad', got {index_unit!r}")
        self.lambda_c = (lambda_c1, lambda_c2)
        self.c3, self.c4 = c3, c4
        self._index_scale = RAD_TO_DEG if index_unit == "deg" else 1.0
        self.lambdas: tuple[float, float] = (0.0, 0.0)

    def change_index(self, x: np.ndarray, y: np.ndarray, sub: _SubModel) -> float:
        """λ_k of eq. (43): |mean error| of the newest N_u rows under the previous model."""
        nu = self.update_every
        e = y[-nu:] - x[-nu:] @ sub.theta - sub.bias
        return abs(float(np.sum(e))) / nu * self._index_scale

    def _reweighting(self, n: int) -> np.ndarray:
        """Eq. (44): c3 for the older half of the window, c4 for the newer half."""
        w = np.full(n, self.c4)
        w[: n // 2] = self.c3
        return w

    def _identify(self) -> None:
        x1, y1, x2, y2 = self._window_data()
        if self.identified:
            lam1 = self.change_index(x1, y1, self.sub1)
            lam2 = self.change_index(x2, y2, self.sub2)
        else:  # no previous identified model yet: the index is undefined
            lam1 = lam2 = 0.0
        self.lambdas = (lam1, lam2)
        changed1 = lam1 > self.lambda_c[0]
        changed2 = lam2 > self.lambda_c[1]
        s1 = self._solve(x1, y1, self._reweighting(y1.shape[0]) if changed1 else None)
        s2 = self._solve(x2, y2, self._reweighting(y2.shape[0]) if changed2 else None)
        flags = self._accept(s1.theta, s1.bias, s2.theta, s2.bias, reject_negative=True)
        self._record(
            lambda1=lam1, lambda2=lam2, reweighted1=changed1, reweighted2=changed2, **flags
        )

"""Front ends of the Nomoto regression: where the derivatives in the rows of eq. (36) come from.

The rows of Liu et al. (2019) eq. (35)–(37) are defined once
(:func:`shipgym.identification.nomoto.regression_rows`) on *increments* ψ_n ≈ hⁿ·ψ⁽ⁿ⁾ of the
heading and δ_1 ≈ h·δ′ of the rudder at each row time; two replaceable sources provide them:

* ``"differences"`` (:class:`DifferencesFrontEnd`, the paper's, the default): ψ_n = Δⁿψ, the
  forward differences of eq. (32), and δ_1 = Δδ.  With heading noise of σ the noise of Δ³ψ is
  σ·√20; at h = 0.01 s on the Case 3 ship the signal Δ³ψ is ≈ 1e-6 rad, so a σ = 0.2° sensor
  leaves eq. (36) pure noise (README, "Identification").
* ``"svf"`` (:class:`SVFFrontEnd`, an extension beyond the paper, from continuous-time
  identification: Young 1981; Garnier, Mensler & Richard 2003, the CONTSID approach): a
  Hampel outlier filter on the heading, then the state-variable filter
  F(s) = (λ/(s + λ))⁴ on ψ and on δ alike.  Its states are ψf, ψf′, ψf″, ψf‴, the *exact*
  derivatives of the filtered heading, and ψ_n = hⁿ·ψf⁽ⁿ⁾, δ → δf, δ_1 = h·δf′.  Eq. (1) is
  linear in ψ and δ, so the filtered signals obey it with the same K, T1, T2, T3 (the constant
  d0 passes F unchanged; β·r³ becomes β·(ψf′)³, an approximation, and β is not identifiable
  at these yaw rates anyway).  A filter of bandwidth λ cannot resolve a time constant much
  shorter than 1/λ (T2 = 0.0247 s of the Case 3 ship before its change, against
  1/λ = 0.33 s): the fit then returns no real T1, T2 and the identifiers keep their model.

The servo rows (37) take δ and δc as sampled, in both front ends (δ is not measured with
noise).

Both are streaming and causal: ``push`` takes the next samples and returns the signals of the
rows that became complete, carrying every state (heading unwrapping, difference tail, outlier
window, filter states) across calls, so an online identifier's window slides over one
continuous stream.  A row for sample k is complete once sample k + ``delay`` has arrived:
3 samples for the differences; for the SVF the Hampel look-ahead (window − 1)/2 plus one
sample (the servo row's Δδ), i.e. 4 samples = 0.04 s at h = 0.01 s with the default 7-sample
window.  ψ and δ go through the same delay and the same filter, so they stay aligned.
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from typing import Any, ClassVar, Protocol

import numpy as np
from scipy.linalg import expm

from shipgym.angles import unwrap_array
from shipgym.identification.errors import (
    IdentificationError,
    check_log_arrays,
    check_sampling_step,
    describe_nonfinite,
)

#: the two sources of the derivatives
FRONT_ENDS = ("differences", "svf")
#: SVF bandwidth λ [rad/s] (≈ 3 rad/s suits the nomoto2 ships; docs/identification.md)
SVF_BANDWIDTH = 3.0
#: order of the SVF (λ/(s+λ))ⁿ: states up to the 3rd derivative of eq. (36)
SVF_ORDER = 4
#: γ of the LS-SVM on the SVF rows.  The paper's γ = 1e15 makes the ridge ½‖θ‖² negligible
#: on its difference rows; the filtered rows are smaller (the filter removes what is above
#: λ), and at 1e15 the ridge biases weakly excited windows (noise-free Case 1 with the SVF:
#: T2 +1480 %, T3 +12000 %; at 1e20 all of K, T1, T2, T3 within 0.1 %; Case 3 ACE unchanged)
SVF_GAMMA = 1e20
#: γ of Liu et al. (2019) §4 (the differences)
PAPER_GAMMA = 1e15
#: Hampel window [samples, odd, centred] and threshold [× 1.4826·MAD]
OUTLIER_WINDOW = 7
OUTLIER_THRESHOLD = 3.0
#: MAD → standard deviation of a Gaussian
MAD_TO_SIGMA = 1.4826
#: rows discarded after the SVF starts [in filter time constants 1/λ]: the filter starts at
#: the first sample's steady state, which the plant need not be in (e.g. d0 acting on a ship
#: at rest); (λt)³/6·e^{−λt} < 2e-3 after 12/λ
SVF_SETTLE_TIME_CONSTANTS = 12.0


def forward_difference(f: np.ndarray, order: int) -> np.ndarray:
    """Δⁿ_h[f](t_k) = Σ_i (−1)^i C(n, i) f(t_k + (n − i)h), eq. (32); length len(f) − n."""
    f = np.asarray(f, dtype=float)
    if order == 0:
        return f.copy()
    n = f.shape[0] - order
    out = np.zeros(n)
    for i in range(order + 1):
        out += (-1) ** i * math.comb(order, i) * f[order - i : order - i + n]
    return out


@dataclasses.dataclass(frozen=True)
class RegressionSignals:
    """What the rows of eq. (35)–(37) need, one entry per row time t_k (rad, SI).

    ``psi1``, ``psi2``, ``psi3``: heading increments ψ_n ≈ hⁿψ⁽ⁿ⁾; ``delta``, ``delta1``: the
    rudder δ and its increment ≈ h·δ′ as they enter eq. (36); ``servo_delta``,
    ``servo_delta1``, ``servo_command``: δ, Δδ and δc of the servo rows (37).
    """

    psi1: np.ndarray
    psi2: np.ndarray
    psi3: np.ndarray
    delta: np.ndarray
    delta1: np.ndarray
    servo_delta: np.ndarray
    servo_delta1: np.ndarray
    servo_command: np.ndarray

    def __len__(self) -> int:
        return int(self.psi3.shape[0])

    @classmethod
    def empty(cls) -> RegressionSignals:
        return cls(*(np.zeros(0) for _ in dataclasses.fields(cls)))

    @classmethod
    def concatenate(cls, parts: list[RegressionSignals]) -> RegressionSignals:
        """The signals of consecutive parts, in order."""
        parts = [p for p in parts if len(p)]
        if not parts:
            return cls.empty()
        if len(parts) == 1:
            return parts[0]
        return cls(
            *(np.concatenate([getattr(p, f.name) for p in parts]) for f in dataclasses.fields(cls))
        )


def difference_signals(
    psi: np.ndarray, delta: np.ndarray, delta_c: np.ndarray
) -> RegressionSignals:
    """The paper's source (eq. (32)): Δψ, Δ²ψ, Δ³ψ, δ, Δδ for rows t_0 … t_{n−4}."""
    n = psi.shape[0] - 3
    d1 = forward_difference(psi, 1)[:n]
    d2 = forward_difference(psi, 2)[:n]
    d3 = forward_difference(psi, 3)
    dd = forward_difference(delta, 1)[:n]
    return RegressionSignals(d1, d2, d3, delta[:n], dd, delta[:n], dd, delta_c[:n])


class FrontEnd(Protocol):
    """A streaming source of :class:`RegressionSignals` (see the module doc)."""

    name: str
    delay: int  # samples: a row for sample k is returned once sample k + delay has arrived

    def push(
        self, psi: np.ndarray, delta: np.ndarray, delta_c: np.ndarray
    ) -> tuple[RegressionSignals, str | None]:
        """Signals of the rows completed by these samples, and a note on the data (or None)."""
        ...


def _columns(psi: Any, delta: Any, delta_c: Any) -> np.ndarray:
    """The samples as (n, 3) columns; arrays of different lengths are an error naming them
    (non-finite samples are dropped samples here: each front end says what it did)."""
    if (
        type(psi) is type(delta) is type(delta_c) is np.ndarray
        and psi.dtype == delta.dtype == delta_c.dtype == np.float64
        and psi.ndim == delta.ndim == delta_c.ndim == 1
        and psi.shape == delta.shape == delta_c.shape
    ):  # the usual case (the env's samples): no conversion or check needed
        out = np.empty((psi.shape[0], 3))
        out[:, 0], out[:, 1], out[:, 2] = psi, delta, delta_c
        return out
    arrays = [np.asarray(a, float).ravel() for a in (psi, delta, delta_c)]
    return np.column_stack(check_log_arrays(arrays, finite=False))


class DifferencesFrontEnd:
    """The paper's forward differences, streamed: the last 3 samples are carried to the next
    call; a non-finite (dropped) sample breaks the difference chain, so rows are only built
    within unbroken runs of samples (no difference spans a gap)."""

    name: ClassVar[str] = "differences"
    delay: ClassVar[int] = 3

    def __init__(self) -> None:
        self._tail = np.zeros((0, 3))  # last raw samples (ψ, δ, δc) not yet usable

    def push(
        self, psi: np.ndarray, delta: np.ndarray, delta_c: np.ndarray
    ) -> tuple[RegressionSignals, str | None]:
        new = _columns(psi, delta, delta_c)
        if new.shape[0] and np.isfinite(new).all():  # the usual case: one unbroken run
            return self._run(new), None
        finite = np.all(np.isfinite(new), axis=1)
        note = (
            None
            if np.all(finite)
            else f"non-finite samples ({describe_nonfinite(new)}): difference chain restarted"
        )
        parts = []
        start = 0
        breaks = np.flatnonzero(~finite)
        for stop in [*breaks.tolist(), new.shape[0]]:
            if stop > start:
                parts.append(self._run(new[start:stop]))
            if stop < new.shape[0]:
                self._tail = np.zeros((0, 3))  # a gap: no difference across it
            start = stop + 1
        return RegressionSignals.concatenate(parts), note

    def _run(self, new: np.ndarray) -> RegressionSignals:
        raw = np.vstack([self._tail, new])
        if self._tail.shape[0]:  # keep heading continuous across calls
            raw[:, 0] = unwrap_array(raw[:, 0])
        if raw.shape[0] < 4:
            self._tail = raw
            return RegressionSignals.empty()
        signals = difference_signals(raw[:, 0], raw[:, 1], raw[:, 2])
        self._tail = raw[-3:]
        return signals


class HampelFilter:
    """Streaming Hampel outlier filter: each sample is compared with the median of the
    ``window`` samples centred on it; it is replaced by that median when it is further than
    ``threshold``·1.4826·MAD from it (MAD: median absolute deviation in the window), or when it
    is not finite (the median of the window's finite samples).

    Causal with a delay of (window − 1)/2 samples: ``push`` returns the cleaned samples whose
    window is complete (at the start of the stream the window is cut at the first sample).
    ``replaced`` counts the replaced samples.
    """

    def __init__(self, window: int = OUTLIER_WINDOW, threshold: float = OUTLIER_THRESHOLD) -> None:
        if isinstance(window, bool) or not isinstance(window, int | np.integer) or window < 3:
            raise IdentificationError(f"outlier_window must be an odd integer ≥ 3, got {window!r}")
        if window % 2 == 0:
            raise IdentificationError(f"outlier_window must be odd (centred), got {window}")
        if not (isinstance(threshold, int | float) and math.isfinite(threshold) and threshold > 0):
            raise IdentificationError(
                f"outlier_threshold must be finite and > 0, got {threshold!r}"
            )
        self.window = int(window)
        self.threshold = float(threshold)
        self.delay = (self.window - 1) // 2
        self._buffer = np.zeros(0)  # raw samples from (next centre − delay) to the newest
        self._past = 0  # samples in the buffer before the next centre (< delay at the start)
        self.replaced = 0
        self._offsets: dict[int, np.ndarray] = {}  # window gather index per window count

    def push(self, x: np.ndarray) -> np.ndarray:
        """Cleaned samples of every centre completed by ``x`` (in order)."""
        buf = np.concatenate([self._buffer, np.asarray(x, dtype=float).ravel()])
        half = self.delay
        start, stop = self._past, buf.shape[0] - half  # centres start … stop − 1 in buf
        if stop <= start:
            self._buffer = buf
            return np.zeros(0)
        centre = buf[start:stop]
        cut = min(max(half - start, 0), stop - start)  # stream start: windows cut at buf[0]
        if cut == 0:  # every window full (after the stream's first samples)
            med, mad = self._full_median_mad(buf, start - half, centre.shape[0])
            return self._replace(buf, centre, med, mad, stop)
        med, mad = np.empty_like(centre), np.empty_like(centre)
        for i in range(cut):
            m_i, d_i = _median_mad(buf[: start + i + half + 1][None, :])
            med[i], mad[i] = m_i[0], d_i[0]
        if cut < centre.shape[0]:
            first = start + cut - half  # buf index of the first full window
            med[cut:], mad[cut:] = self._full_median_mad(buf, first, centre.shape[0] - cut)
        return self._replace(buf, centre, med, mad, stop)

    def _replace(
        self, buf: np.ndarray, centre: np.ndarray, med: np.ndarray, mad: np.ndarray, stop: int
    ) -> np.ndarray:
        """The centres with the outliers replaced by their window's median; keeps the
        samples the next windows need."""
        bad = ~np.isfinite(centre) | (np.abs(centre - med) > self.threshold * MAD_TO_SIGMA * mad)
        out = np.where(bad, med, centre)
        self.replaced += int(np.count_nonzero(bad & np.isfinite(med)))
        keep = max(stop - self.delay, 0)
        self._buffer, self._past = buf[keep:], stop - keep
        return out

    def _full_median_mad(
        self, buf: np.ndarray, first: int, count: int
    ) -> tuple[np.ndarray, np.ndarray]:
        """Median and MAD of the ``count`` full windows buf[first + i : first + i + window]:
        an odd window's median is its middle order statistic, picked by one in-place
        partition of a gathered copy (the value ``np.median`` returns, without its overhead);
        a window with a non-finite entry goes through :func:`_median_mad`."""
        index = self._offsets.get(count)
        if index is None:
            index = np.arange(count)[:, None] + np.arange(self.window)[None, :]
            self._offsets = {count: index}  # one count per control period, in practice
        windows = buf[index + first]
        if not np.isfinite(windows).all():
            return _median_mad(windows)
        k = self.delay  # middle of an odd window
        windows.partition(k, axis=1)
        med = windows[:, k].copy()
        deviation = np.abs(windows - med[:, None])  # the same multiset, in another order
        deviation.partition(k, axis=1)
        return med, deviation[:, k]


def _median_mad(windows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Median and median absolute deviation of each row (non-finite entries ignored)."""
    if np.all(np.isfinite(windows)):
        med = np.median(windows, axis=1)
        return med, np.median(np.abs(windows - med[:, None]), axis=1)
    w = np.where(np.isfinite(windows), windows, np.nan)
    with warnings.catch_warnings():  # an all-NaN window: NaN out, the caller holds
        warnings.simplefilter("ignore", RuntimeWarning)
        med = np.nanmedian(w, axis=1)
        return med, np.nanmedian(np.abs(w - med[:, None]), axis=1)


class StateVariableFilter:
    """F(s) = (λ/(s + λ))ⁿ as ẋ = A·x + B·u with x = [yf, yf′, …, yf⁽ⁿ⁻¹⁾] (companion form),
    discretised exactly for an input held over each step h (zero-order hold):
    [Ad Bd; 0 1] = exp([A B; 0 0]·h).  λ [rad/s], h [s]; every state is an exact derivative
    of the filter output yf."""

    def __init__(self, bandwidth: float, h: float, order: int = SVF_ORDER) -> None:
        h = check_sampling_step(h)
        if not (isinstance(bandwidth, int | float) and math.isfinite(bandwidth) and bandwidth > 0):
            raise IdentificationError(
                f"svf_bandwidth must be finite and > 0 rad/s, got {bandwidth!r}"
            )
        self.bandwidth, self.h, self.order = float(bandwidth), h, order
        lam, n = self.bandwidth, order
        a = np.zeros((n, n))
        a[np.arange(n - 1), np.arange(1, n)] = 1.0
        # (s + λ)ⁿ = sⁿ + Σ_k C(n, k) λ^{n−k} s^k
        a[n - 1] = [-math.comb(n, k) * lam ** (n - k) for k in range(n)]
        b = np.zeros(n)
        b[n - 1] = lam**n
        self.A, self.B = a, b
        block = np.zeros((n + 1, n + 1))
        block[:n, :n], block[:n, n] = a * h, b * h
        m = expm(block)
        self.Ad, self.Bd = m[:n, :n], m[:n, n]
        self._block: tuple[np.ndarray, np.ndarray] | None = None

    def steady_state(self, u0: np.ndarray) -> np.ndarray:
        """States (n, c) at rest under constant inputs u0 (c,): yf = u0, derivatives 0."""
        x = np.zeros((self.order, np.size(u0)))
        x[0] = u0
        return x

    def run(self, u: np.ndarray, x0: np.ndarray) -> np.ndarray:
        """States after each input: x_{j+1} = Ad·x_j + Bd·u_j for u (m, c) from x0 (n, c);
        returns (m, n, c).  Computed a block at a time from the powers of Ad and the Markov
        parameters Ad^k·Bd (the same recursion, vectorised)."""
        u = np.asarray(u, dtype=float)
        out = np.empty((u.shape[0], *x0.shape))
        x = x0
        for start in range(0, u.shape[0], self.BLOCK):
            block = u[start : start + self.BLOCK]
            k = block.shape[0]
            powers, markov = self._block_matrices()
            states = powers[:k] @ x + markov[:k, :, :k] @ block
            out[start : start + k] = states
            x = states[-1]
        return out

    #: samples per vectorised block of :meth:`run`
    BLOCK: ClassVar[int] = 128

    def _block_matrices(self) -> tuple[np.ndarray, np.ndarray]:
        """Ad^{j+1} (B, n, n) and the lower-triangular Ad^{j−i}·Bd as (B, n, B), built once."""
        if self._block is None:
            n, b = self.order, self.BLOCK
            powers = np.empty((b, n, n))
            impulse = np.empty((b, n))  # Ad^k·Bd
            p, g = np.eye(n), self.Bd.copy()
            for j in range(b):
                impulse[j] = g
                p = self.Ad @ p
                powers[j] = p
                g = self.Ad @ g
            lag = np.arange(b)[:, None] - np.arange(b)[None, :]
            markov = np.where((lag >= 0)[..., None], impulse[np.clip(lag, 0, None)], 0.0)
            self._block = (powers, np.ascontiguousarray(markov.transpose(0, 2, 1)))
        return self._block


@dataclasses.dataclass(frozen=True)
class FrontEndSettings:
    """Which front end and its settings (module doc).  ``outlier_filter``: the Hampel filter
    of the SVF front end (None or True: on, False: off); the differences have none (their
    rows stay the paper's, bit for bit)."""

    front_end: str = "differences"
    svf_bandwidth: float = SVF_BANDWIDTH  # λ [rad/s]
    outlier_filter: bool | None = None
    outlier_window: int = OUTLIER_WINDOW  # samples, odd, centred
    outlier_threshold: float = OUTLIER_THRESHOLD  # × 1.4826·MAD

    def __post_init__(self) -> None:
        if self.front_end not in FRONT_ENDS:
            raise IdentificationError(
                f"front_end must be one of {', '.join(FRONT_ENDS)}, got {self.front_end!r}"
            )
        if self.front_end == "differences" and self.outlier_filter:
            # measured: a spike replaced by its window median is still off by up to one
            # sample's increment (≈ 1e-3 rad), 1000 × the Δ³ψ signal: the differences need
            # clean data, and the outlier filter belongs to the SVF front end
            raise IdentificationError(
                "outlier_filter=True needs front_end='svf' (the differences have no outlier filter)"
            )
        if self.use_outlier_filter:
            HampelFilter(self.outlier_window, self.outlier_threshold)  # validates
        if self.front_end == "svf":
            StateVariableFilter(self.svf_bandwidth, 1.0)  # validates λ

    @property
    def gamma(self) -> float:
        """The LS-SVM γ that goes with this front end (:data:`SVF_GAMMA`, :data:`PAPER_GAMMA`)."""
        return SVF_GAMMA if self.front_end == "svf" else PAPER_GAMMA

    @property
    def use_outlier_filter(self) -> bool:
        return self.front_end == "svf" and self.outlier_filter is not False

    def make(self, h: float) -> FrontEnd:
        """A fresh streaming front end for samples at spacing h [s]."""
        h = check_sampling_step(h)
        hampel = (
            HampelFilter(self.outlier_window, self.outlier_threshold)
            if self.use_outlier_filter
            else None
        )
        if self.front_end == "svf":
            return SVFFrontEnd(h, self.svf_bandwidth, hampel)
        return DifferencesFrontEnd()


class _Cleaner:
    """Heading unwrapping and outlier removal in front of a derivative source: ψ is unwrapped
    continuously across calls, cleaned by the Hampel filter (if any), and δ, δc are delayed
    alike; a non-finite δ or δc, or a non-finite ψ without the filter, holds the last value."""

    def __init__(self, hampel: HampelFilter | None) -> None:
        self.hampel = hampel
        self.delay = hampel.delay if hampel is not None else 0
        self._last = np.zeros(3)  # last finite (unwrapped ψ, δ, δc)
        self._started = False
        self._waiting = np.zeros((0, 2))  # δ, δc waiting for their ψ to leave the filter
        self._held = 0.0  # last cleaned heading

    def push(self, new: np.ndarray) -> tuple[np.ndarray, str | None]:
        """Aligned cleaned samples (k, 3) completed by ``new`` (m, 3), and a note."""
        new = new.copy()
        finite = np.isfinite(new)
        if new.shape[0] and finite.all():  # the usual case: nothing to replace or hold
            if not self._started:
                self._last = new[0].copy()
                self._started = True
            new[:, 0] = unwrap_array(np.concatenate(((self._last[0],), new[:, 0])))[1:]
            self._last = new[-1].copy()
            return self._filtered(new), None
        note = None
        if not self._started and new.shape[0]:
            first = [new[finite[:, j], j][:1] for j in range(3)]
            self._last = np.array([f[0] if f.size else 0.0 for f in first])
            self._started = True
        if not np.all(finite):
            note = (
                f"non-finite samples ({describe_nonfinite(new)}) replaced ("
                + ("outlier filter's median" if self.hampel is not None else "last value held")
                + ")"
            )
        psi = new[:, 0]
        ok = finite[:, 0]
        if np.any(ok):  # unwrap the finite headings continuously across calls
            psi[ok] = np.unwrap(np.concatenate(([self._last[0]], psi[ok])))[1:]
        for j in (1, 2) if self.hampel is not None else (0, 1, 2):
            col = new[:, j]
            for i in np.flatnonzero(~np.isfinite(col)):
                col[i] = col[i - 1] if i > 0 else self._last[j]
        for j in range(3):
            good = np.isfinite(new[:, j])
            if np.any(good):
                self._last[j] = new[good, j][-1]
        return self._filtered(new), note

    def _filtered(self, new: np.ndarray) -> np.ndarray:
        """The outlier filter's output for unwrapped samples (k, 3), δ and δc delayed alike."""
        if self.hampel is None:
            return new
        cleaned = self.hampel.push(new[:, 0])
        waiting = np.vstack([self._waiting, new[:, 1:]])
        k = cleaned.shape[0]
        for i in np.flatnonzero(~np.isfinite(cleaned)):  # a window without a finite sample
            cleaned[i] = cleaned[i - 1] if i > 0 else self._held
        if k:
            self._held = cleaned[-1]
        self._waiting = waiting[k:]
        out = np.empty((k, 3))
        out[:, 0], out[:, 1:] = cleaned, waiting[:k]
        return out


class SVFFrontEnd:
    """Outlier filter + state-variable filter (module doc), streamed.

    The filters of ψ and δ start at the first (cleaned) sample's steady state; the rows of
    the first ``settle`` samples (12/λ: the start transient) are discarded.  The servo row of
    sample j needs δ_{j+1}, so the rows of sample j leave with sample j + 1.
    """

    name: ClassVar[str] = "svf"

    def __init__(self, h: float, bandwidth: float, hampel: HampelFilter | None) -> None:
        self.h = check_sampling_step(h)
        self.filter = StateVariableFilter(bandwidth, self.h)
        self.cleaner = _Cleaner(hampel)
        self.delay = self.cleaner.delay + 1
        self.settle = math.ceil(SVF_SETTLE_TIME_CONSTANTS / (self.filter.bandwidth * self.h))
        self._states: np.ndarray | None = None  # (order, 2): ψ and δ channels
        self._pending: tuple[np.ndarray, float, float] | None = None  # (states, δ, δc) of j
        self._count = 0  # aligned samples filtered so far

    def push(
        self, psi: np.ndarray, delta: np.ndarray, delta_c: np.ndarray
    ) -> tuple[RegressionSignals, str | None]:
        aligned, note = self.cleaner.push(_columns(psi, delta, delta_c))
        m = aligned.shape[0]
        if m == 0:
            return RegressionSignals.empty(), note
        u = aligned[:, :2]  # ψ, δ filtered alike
        if self._states is None:
            self._states = self.filter.steady_state(u[0])
        states = self.filter.run(u, self._states)  # (m, order, 2)
        self._states = states[-1]
        first = self._count
        self._count += m
        # rows for samples first − 1 (pending) … first + m − 2; sample first + m − 1 waits
        if self._pending is not None:
            states = np.concatenate([self._pending[0][None], states])
            delta_s = np.concatenate(([self._pending[1]], aligned[:, 1]))
            command = np.concatenate(([self._pending[2]], aligned[:, 2]))
            index0 = first - 1
        else:
            delta_s, command, index0 = aligned[:, 1], aligned[:, 2], first
        self._pending = (states[-1], float(delta_s[-1]), float(command[-1]))
        skip = min(max(self.settle - index0, 0), states.shape[0] - 1)
        x, d, c = states[skip:-1], delta_s[skip:], command[skip:]
        h = self.h
        signals = RegressionSignals(
            psi1=h * x[:, 1, 0],
            psi2=h**2 * x[:, 2, 0],
            psi3=h**3 * x[:, 3, 0],
            delta=x[:, 0, 1],
            delta1=h * x[:, 1, 1],
            servo_delta=d[:-1],
            servo_delta1=np.diff(d),
            servo_command=c[:-1],
        )
        return signals, note

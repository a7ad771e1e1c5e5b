"""LQR track-keeping with continuous-LS adaptation (Borkowski 2018): ``lqr``, ``adaptive_lqr``.

Borkowski (2018) §4.  In the relative frame of the active leg (eq. (25)–(26): origin at the
last reached waypoint P_i, axis along P_iP_{i+1}) the state is x = [y_r, ψ_r, r] with the
cross-track error y_r [m], the relative course ψ_r = wrap(ψ − φ_ro) [rad] and the yaw rate
r [rad/s]; linearised about the leg (sin ψ_r ≈ ψ_r) with the first-order Nomoto model
ṙ = −a·r + c·δ (eq. (31)), eq. (28):

    A = [[0, U, 0], [0, 0, 1], [0, 0, −a]],   B = [0, 0, c]ᵀ,

U the ship's speed ("as an approximation the actual speed can be accepted").  The cost
eq. (29)–(30), Rx = diag(λy, λψ, 0), Ru = λδ (λy = 1/2000 1/m², λψ = 1, λδ = 5 of §5).
The gain comes from the continuous algebraic Riccati equation (``scipy.linalg.
solve_continuous_are``): AᵀP + PA − PBRu⁻¹BᵀP + Rx = 0, K = Ru⁻¹BᵀP, δ = −K·x.  The paper
writes eq. (4)–(5) with P negative definite and u* = +Ru⁻¹BᵀPx; that is the same law with
P → −P.  Legs switch as the env does (``context.new_tracker()``; on ``mariner_track`` the
along-track rule eq. (27), |P_iP_{i+1}| − x_r < R, R = 500 m).

``lqr`` keeps the gain of the initial guess (a0, c0).  ``adaptive_lqr`` feeds the fine-step
samples of the yaw rate and the (actual) rudder angle to the continuous least squares of
eq. (12)–(15), (32)–(34) (:class:`shipgym.identification.continuous_ls.ContinuousLeastSquares`,
started at
(a0, c0)) and re-solves the Riccati equation with the current estimates (certainty
equivalence, Fig. 1).  The sliding-mode term of eq. (24) is not used: the paper's own
experiments (§5) run the plain LQR (4) with the identified model, and eq. (24) needs bounds
o_i the paper does not give.

Choices where the paper is silent (all options of the controllers):

* **Initial guess.** On ``mariner`` the paper's a0 = 0.02 1/s, c0 = 0.002 1/s² (§5; the
  plant's linear part is a1 = 0.018, a3 = 0.001).  On other ships, unless given, the guess is
  the nominal model's first-order Nomoto approximation
  ``shipgym.identification.first_order_nomoto(context.nominal_model)`` → (K, T): a0 = 1/T,
  c0 = K/T (for ṙ = (K·δ − r)/T).
* **λy on other ships.** ``lambda_y=None`` (default) is 1/2000·(172 m / L)², i.e. the paper's
  1/2000 for its 172 m Mariner and the same cost in ship lengths on other ships (with a and c
  in 1/s, 1/s², the Froude-scaled problem has the same gains in L and L/U units).  With the
  paper's 1/2000 on the 0.95 m nomoto2 the cross-track weight is 3·10⁴ times too weak (its
  d0 yaw bias alone would hold it 4 m = 4 L off the path).  Pass ``lambda_y=1/2000`` for
  the literal weight.
* **Speed U.** ``speed="measured"``: speed over ground from the last two measured positions,
  |p_k − p_{k−1}|/Ts (the context's nominal speed at the first step); ``"nominal"``: the
  context's nominal speed throughout.
* **Steering-gear limits.** The plant clips the angle and limits the rate of the actual
  rudder itself; the command respects both too: |δc| ≤ context.rudder_limit and
  |δc,k − δc,k−1| ≤ δ̇max·Ts with δ̇max the nominal model's ``rudder_rate_limit`` (0.066
  rad/s on the Mariner, §5; no limit where the model has none, e.g. nomoto2).  So the
  command itself is a rudder trajectory the gear can follow.
* **Re-solving.** The Riccati equation (≈ 0.07 ms, :func:`solve_care`) is re-solved when a,
  c or U has moved by more than ``resolve_tolerance`` (1 %) relative to the values of the
  current gain.
* **Projection (our addition).** The estimates the gain uses are clipped to
  [x0/F, x0·F] around the initial guess (F = ``projection_factor`` = 10; ``None`` switches it
  off): ĉ → 0 would make the gain blow up (B loses rank), and the linear regression has no
  bias term, so a constant yaw disturbance (nomoto2's d0, a current) drags ĉ towards 0
  while the ship holds a steady rudder.  The raw estimates are recorded unclipped
  (``history``; ``episode_stats()``: ``a_hat``, ``c_hat``, ``projected_steps``).
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np
from scipy.linalg import solve_continuous_are

from shipgym.angles import wrap_angle
from shipgym.envs.context import ControllerContext
from shipgym.identification.continuous_ls import ContinuousLeastSquares
from shipgym.identification.nominal import first_order_nomoto
from shipgym_baselines.classical.drift import course_and_drift
from shipgym_baselines.policy import check_action_mode
from shipgym_baselines.records.chosen import tuned_settings

#: Borkowski (2018) §5: initial estimates on the Mariner (a0 [1/s], c0 [1/s²])
PAPER_INITIAL_GUESS = {"mariner": (0.02, 0.002)}
#: Borkowski (2018) §5: λy [1/m²], λψ [1/rad²], λδ [1/rad²], for the 172 m Mariner
PAPER_LAMBDA_Y = 1.0 / 2000.0
PAPER_LAMBDA_PSI = 1.0
PAPER_LAMBDA_DELTA = 5.0
PAPER_SHIP_LENGTH = 172.0  # [m]


@dataclasses.dataclass(frozen=True)
class LQRWeights:
    """Cost weights of Borkowski (2018) eq. (29)–(30)."""

    lambda_y: float = PAPER_LAMBDA_Y  # [1/m²]
    lambda_psi: float = PAPER_LAMBDA_PSI  # [1/rad²]
    lambda_delta: float = PAPER_LAMBDA_DELTA  # [1/rad²]

    def __post_init__(self) -> None:
        for name in ("lambda_y", "lambda_psi"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v >= 0):
                raise ValueError(f"LQRWeights.{name} must be finite and ≥ 0, got {v!r}")
        if not (math.isfinite(self.lambda_delta) and self.lambda_delta > 0):
            raise ValueError(f"LQRWeights.lambda_delta must be > 0, got {self.lambda_delta!r}")

    @property
    def Rx(self) -> np.ndarray:
        """State weight diag(λy, λψ, 0), eq. (30)."""
        return np.diag([self.lambda_y, self.lambda_psi, 0.0])

    @property
    def Ru(self) -> np.ndarray:
        """Input weight [λδ], eq. (30)."""
        return np.array([[self.lambda_delta]])


def track_model(a: float, c: float, speed: float) -> tuple[np.ndarray, np.ndarray]:
    """(A, B) of Borkowski (2018) eq. (28) for x = [y_r, ψ_r, r], u = δ.

    a [1/s], c [1/s²] of ṙ = −a·r + c·δ; speed U [m/s].
    """
    A = np.array([[0.0, speed, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -a]])
    B = np.array([[0.0], [0.0], [c]])
    return A, B


def lqr_gain(
    a: float, c: float, speed: float, weights: LQRWeights = LQRWeights()
) -> tuple[np.ndarray, np.ndarray]:
    """LQR gain K (1×3) and Riccati solution P (3×3) of eq. (4)–(5), δ = −K·x.

    P ≻ 0 solves AᵀP + PA − PBRu⁻¹BᵀP + Rx = 0 (the paper's eq. (5) with P → −P) and
    K = Ru⁻¹BᵀP.  Raises ValueError if (A, B) is not stabilisable (c = 0 or U = 0).
    """
    if not all(math.isfinite(v) for v in (a, c, speed)):
        raise ValueError(f"lqr_gain: non-finite model a={a}, c={c}, speed={speed}")
    if c == 0.0 or speed == 0.0:
        raise ValueError(f"lqr_gain: (A, B) not stabilisable with c={c}, speed={speed}")
    A, B = track_model(a, c, speed)
    P = solve_care(A, B, weights.Rx, weights.Ru)
    K = np.linalg.solve(weights.Ru, B.T @ P)
    return K, P


def solve_care(A: np.ndarray, B: np.ndarray, Q: np.ndarray, R: np.ndarray) -> np.ndarray:
    """Stabilising solution P of AᵀP + PA − PBR⁻¹BᵀP + Q = 0 for small systems.

    From the stable invariant subspace [X1; X2] of the Hamiltonian
    H = [[A, −BR⁻¹Bᵀ], [−Q, −Aᵀ]]: P = X2·X1⁻¹ (≈ 40 µs for n = 3, against ≈ 1 ms for
    ``scipy.linalg.solve_continuous_are``'s ordered QZ, which remains the fallback when the
    eigenvectors are ill-conditioned or the residual is not at rounding level).
    """
    n = A.shape[0]
    G = B @ np.linalg.solve(R, B.T)
    H = np.block([[A, -G], [-Q, -A.T]])
    w, V = np.linalg.eig(H)
    stable = w.real < 0.0
    if int(stable.sum()) == n:
        X1, X2 = V[:n, stable], V[n:, stable]
        if np.linalg.cond(X1) < 1e8:
            P = np.real(np.linalg.solve(X1.T, X2.T).T)  # X2·X1⁻¹
            P = 0.5 * (P + P.T)
            residual = A.T @ P + P @ A - P @ G @ P + Q
            scale = np.abs(Q).max() + np.abs(A.T @ P).max() + np.abs(P @ G @ P).max()
            if np.abs(residual).max() <= 1e-10 * scale:
                return P
    return solve_continuous_are(A, B, Q, R)


def length_scaled_lambda_y(ship_length: float) -> float:
    """λy [1/m²] with the paper's cross-track cost in ship lengths: 1/2000·(172 m / L)²."""
    return PAPER_LAMBDA_Y * (PAPER_SHIP_LENGTH / ship_length) ** 2


def initial_guess(context: ControllerContext) -> tuple[float, float]:
    """Default (a0 [1/s], c0 [1/s²]): the paper's on the Mariner, else 1/T, K/T of the nominal."""
    if context.ship in PAPER_INITIAL_GUESS:
        return PAPER_INITIAL_GUESS[context.ship]
    K, T = first_order_nomoto(context.nominal_model)
    return 1.0 / T, K / T


class LQR:
    """Track-keeping LQR of Borkowski (2018) eq. (28)–(30) with a fixed model (a0, c0).

    ``a0`` [1/s], ``c0`` [1/s²]: initial guess (None: see :func:`initial_guess`);
    ``lambda_y`` [1/m²] (None: :func:`length_scaled_lambda_y`), ``lambda_psi``,
    ``lambda_delta``: the weights of eq. (29) (None: the ship's chosen weights with
    ``preset="tuned"``, else the paper's); ``speed``: "measured" | "nominal";
    ``resolve_tolerance``: relative change of (a, c, U) that triggers a new Riccati solve;
    ``preset``: "tuned" reads the ship's section of ``configs/tuning/chosen/<name>.yaml``
    (``shipgym tune lqr``, docs/tuning.md) under the weights given here, "paper" does not;
    ``drift_compensation``: the state's heading error as the course error ψ + β − ψp with
    the measured drift angle β (None: the chosen setting, else off, the paper's).
    """

    name = "lqr"
    kind = "classical"
    adaptive = False

    def __init__(
        self,
        a0: float | None = None,
        c0: float | None = None,
        lambda_y: float | None = None,
        lambda_psi: float | None = None,
        lambda_delta: float | None = None,
        speed: str = "measured",
        resolve_tolerance: float = 0.01,
        preset: str = "tuned",
        drift_compensation: bool | None = None,
    ) -> None:
        if (a0 is None) != (c0 is None):
            raise ValueError("give both a0 and c0, or neither (default initial guess)")
        if c0 is not None and not (math.isfinite(c0) and c0 != 0.0):
            raise ValueError(f"c0 must be finite and non-zero, got {c0!r}")
        if a0 is not None and not math.isfinite(a0):
            raise ValueError(f"a0 must be finite, got {a0!r}")
        if speed not in ("measured", "nominal"):
            raise ValueError(f"speed must be 'measured' or 'nominal', got {speed!r}")
        if not resolve_tolerance >= 0:
            raise ValueError(f"resolve_tolerance must be ≥ 0, got {resolve_tolerance!r}")
        if preset not in ("tuned", "paper"):
            raise ValueError(f"preset must be 'tuned' or 'paper', got {preset!r}")
        self.a0, self.c0 = a0, c0
        self.preset = preset
        #: the weights given here (over the chosen ones at reset)
        self.explicit = {
            k: float(v)
            for k, v in (
                ("lambda_y", lambda_y),
                ("lambda_psi", lambda_psi),
                ("lambda_delta", lambda_delta),
            )
            if v is not None
        }
        if drift_compensation is not None:
            self.explicit["drift_compensation"] = bool(drift_compensation)
        self.speed_source = speed
        self.resolve_tolerance = resolve_tolerance

    # ------------------------------------------------------------------ episode
    def reset(self, context: ControllerContext, seed: int | None = None) -> None:
        check_action_mode(self, context)
        self.ctx = context
        a0, c0 = (self.a0, self.c0) if self.a0 is not None else initial_guess(context)
        self.guess = (float(a0), float(c0))
        chosen = tuned_settings(type(self).name, context.ship) if self.preset == "tuned" else {}
        given = {**chosen, **self.explicit}
        self.weights = LQRWeights(
            given.get("lambda_y", length_scaled_lambda_y(context.ship_length)),
            given.get("lambda_psi", PAPER_LAMBDA_PSI),
            given.get("lambda_delta", PAPER_LAMBDA_DELTA),
        )
        #: the heading error of eq. (25) as the course error ψ + β − ψp (β measured,
        #: classical.drift, as the PID family and L1 compensate it); off: the paper's ψ − ψp
        self.drift_compensation = bool(given.get("drift_compensation", False))
        self._last: dict[str, Any] | None = None
        self.rate_limit = float(getattr(context.nominal_model, "rudder_rate_limit", math.inf))
        self.tracker = context.new_tracker()
        self._started = False
        self._last_position: tuple[float, float] | None = None
        self._last_command = 0.0
        self._design: tuple[float, float, float] | None = None
        self.K = np.zeros((1, 3))
        self.solves = 0
        #: (t [s], â, ĉ) raw estimates per step (adaptive_lqr; empty for the fixed lqr)
        self.history: list[tuple[float, float, float]] = []

    def _model(self, info: dict[str, Any]) -> tuple[float, float]:
        """(a, c) for the gain: the initial guess (the adaptive variant overrides)."""
        return self.guess

    def _speed(self, info: dict[str, Any]) -> float:
        x, y = info["position"]
        speed = self.ctx.nominal_speed
        if self.speed_source == "measured" and self._last_position is not None:
            dx, dy = x - self._last_position[0], y - self._last_position[1]
            moved = math.hypot(dx, dy) / self.ctx.control_period
            if moved > 0.0:
                speed = moved
        self._last_position = (x, y)
        return speed

    def _gain(self, a: float, c: float, speed: float) -> np.ndarray:
        design = self._design
        tol = self.resolve_tolerance
        if design is None or any(
            abs(new - old) > tol * abs(old) for new, old in zip((a, c, speed), design, strict=True)
        ):
            self.K, _ = lqr_gain(a, c, speed, self.weights)
            self._design = (a, c, speed)
            self.solves += 1
        return self.K

    def act(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        x, y = info["position"]
        frame = self.tracker.update(x, y) if self._started else self.tracker.reset(x, y)
        self._started = True
        # Borkowski (2018) eq. (25): state in the frame of the active leg
        heading_error = wrap_angle(info["heading"] - frame.path_angle)
        if self.drift_compensation:  # the course error: ė = U sin(ψ + β − ψp)
            _, drift = course_and_drift(
                info, self._last, self.ctx.control_period, self.ctx.nominal_speed
            )
            heading_error = wrap_angle(heading_error + drift)
            self._last = {"position": (float(x), float(y)), "psi": float(info["heading"])}
        state = np.array([frame.cross_track, heading_error, info["yaw_rate"]])
        a, c = self._model(info)
        speed = self._speed(info)
        K = self._gain(a, c, speed)
        delta_c = -float(K[0] @ state)  # eq. (4), δ = −Ru⁻¹BᵀP·x
        # steering-gear limits on the command: angle, then rate per control period
        limit = self.ctx.rudder_limit
        delta_c = min(limit, max(-limit, delta_c))
        step = self.rate_limit * self.ctx.control_period
        delta_c = min(self._last_command + step, max(self._last_command - step, delta_c))
        self._last_command = delta_c
        return np.array([delta_c / limit], dtype=np.float32)

    def episode_stats(self) -> dict[str, float]:
        return {"riccati_solves": float(self.solves)}


class AdaptiveLQR(LQR):
    """Borkowski (2018) adaptive LQR: the gain of the continuous-LS estimates (â, ĉ).

    Extra options: ``k0`` (initial K(0) = k0·I of eq. (12)–(14)) and ``projection_factor``
    F (estimates used by the gain clipped to [x0/F, x0·F]; None: off).
    """

    name = "adaptive_lqr"
    adaptive = True

    def __init__(
        self,
        a0: float | None = None,
        c0: float | None = None,
        k0: float = 1e-4,
        projection_factor: float | None = 10.0,
        **options: Any,
    ) -> None:
        super().__init__(a0, c0, **options)
        if projection_factor is not None and not projection_factor >= 1.0:
            raise ValueError(f"projection_factor must be ≥ 1 or None, got {projection_factor!r}")
        self.k0 = k0
        self.projection_factor = projection_factor

    def reset(self, context: ControllerContext, seed: int | None = None) -> None:
        super().reset(context, seed)
        a0, c0 = self.guess
        self.estimator = ContinuousLeastSquares(context.fine_step, a0, c0, self.k0)
        self.projected_steps = 0

    def _project(self, value: float, guess: float) -> float:
        f = self.projection_factor
        if f is None:
            return value
        lo, hi = sorted((guess / f, guess * f))
        return min(hi, max(lo, value))

    def _model(self, info: dict[str, Any]) -> tuple[float, float]:
        samples = info.get("samples")
        est = self.estimator
        if samples is not None:  # eq. (32)–(34) on the period's fine samples (x = r, u = δ)
            est.update(samples["r"], samples["delta"])
        a_hat, c_hat = est.a, est.c
        self.history.append((float(info["t"]), a_hat, c_hat))
        a = self._project(a_hat, self.guess[0]) if math.isfinite(a_hat) else self.guess[0]
        c = self._project(c_hat, self.guess[1]) if math.isfinite(c_hat) else self.guess[1]
        if (a, c) != (a_hat, c_hat):
            self.projected_steps += 1
        return a, c

    def episode_stats(self) -> dict[str, float]:
        return {
            **super().episode_stats(),
            "a_hat": self.estimator.a,
            "c_hat": self.estimator.c,
            "projected_steps": float(self.projected_steps),
        }

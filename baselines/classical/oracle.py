"""``oracle`` and ``oracle_frozen``: the privileged references — NMPC on the true plant.

What is achievable on a scenario when the plant is known, and when it is known only as it
was at the start.  At every control step the references read, through the evaluation
loop's privileged channel (:mod:`shipgym_baselines.privileged`; no other controller can
reach it), the true plant now (:class:`shipgym.envs.truth.PlantTruth`).  It is causal: the
true state, the true parameters acting now (after every jump so far) and the disturbances
acting now, never a scheduled event or the current ahead.

* ``oracle`` (revision 5) predicts with the parameters acting now and the disturbances
  acting now, the wave load at its mean after the applied period (below, "Model"): the
  best a controller that knows the change as it happens can do.  Revision 3 read the
  scheduled current ahead, which no controller can know (on the current shifts that
  lowered its cost by up to 1.6×).
* ``oracle_frozen`` predicts with the parameters and disturbances of the episode's start
  (t = 0), held for the whole episode, from the true state at every step: the best a
  controller that never adapts can do on the env's own cost.

Both are references (``kind = "reference"``): shown on every scenario, never ranked; the
oracle's costs are the denominator of the leaderboard's cost ratio, and the frozen one's
over the oracle's is what knowing the change is worth on a trial (its headroom).

**Model.**  The env's own model: the ship's one right-hand side (:meth:`ShipModel.rhs`, its
CasADi form) with the parameter vector named above, integrated by RK4 at the prediction
step h_p (below), rudder servo, rate and angle limits included.  Disturbances: those acting
now over the applied control period; after it the current and the yaw bias as they act now
(a current's fluctuation is correlated over 50 s and more) and the wave load at its mean, 0
(revision 5, ``wave_forecast = "mean"``: a wave's load oscillates with the sea's period of
seconds).  Revision 4 held the wave load of one instant over the whole horizon
(``"held"``), on ``mariner_track`` a yaw load for 268 s that never came (measured with
revision 5's tail on its two smoke trials: 1531 and 1442 held, 519 and 586 with the mean).
Predicting the current's fluctuation at its mean too cost more where it is strong against
the ship's speed (``esso_osaka_current_shift``, 0.02 m/s against 0.41 m/s: 184.2 over its
10 default trials against 121.6 held).

**Objective.**  The env's own stage cost (:func:`shipgym.envs.core.step_reward`), summed
over the control steps of the horizon:

    Σ_k  |e_k|/L + w_ψ|ψ̃_k| + w_δ (δc_k/δmax)² + w_Δ ((δc_k − δc_{k−1})/δmax)²

with |·| smoothed as √(z² + ε²) (ε = ``smooth_abs``), e and ψ̃ measured as the env measures
them: to the active leg.  Legs switch as the env's tracker switches them (the acceptance
circle R0 of Liu eq. (13) or the along-track rule of Borkowski eq. (27)), through latches
q_j ∈ [0, 1] carried in the prediction's state (q_j⁺ = q_j + (1 − q_j)σ_j, σ_j the rule
smoothed over ``switch_width_L``·L and set 2 widths inside its edge), so that a switch is
permanent, as in the env; a PCHIP route enters as its chords ahead of the closest point.
The goal bonus is not in the objective (it is not in the cost either).

**Tail (cost-to-go).**  To that sum the oracle adds one term for the control steps still
to go after the horizon, N_tail = max(0, S/(U·Ts) − N_H): S the path left to the goal from
the ship's present point on the route [m] (the rest of the active leg and the legs after
it, or the arc length left on a PCHIP route), N_H the horizon's steps and U the ship's true
speed over ground now, at least half the cruise speed (``tail_speed = "measured"``: a ship
that is slow has more steps still to go; revisions 1–3 took the cruise speed,
``tail_speed = "cruise"``).  The term (revision 5, ``tail_terms = "approach"``) is

    N_tail · w_ψ · |χ̃_N + atan(e_N/Δ)|,

χ̃_N the course over ground over the horizon's last control period to the active leg (the
direction of the displacement), e_N the cross-track error at the horizon's end and Δ =
``approach_L``·L (2 L): how far the ship at the horizon's end is from the course on which a
look-ahead LOS guidance closes its offset (ė = U sin χ̃ with χ̃ = −atan(e/Δ)), held for the
rest of the route.  A ship on that course costs nothing in the tail whatever its offset
(the offset closes by itself, and the horizon's own |e|/L terms price how soon), while one
heading the wrong way pays N_tail·w_ψ·π.  Reason for the tail (measured, revision 1 missed
the goal on 58 of 472 reference trials): the env's cost has no price on time, so a ship
that turns the wrong way onto a leg and runs along it with e = 0, |ψ̃| = π pays only
w_ψ·π ≈ 0.31 a step, which within one horizon is cheaper than the overshoot of the right
turn; it never reaches the goal and pays that until the time limit.  A one-horizon
terminal weight was measured not to be enough.

Revisions 2–4 held the terminal stage cost, |e_N|/L + w_ψ|ψ̃_N|, for N_tail steps
(``tail_terms = "stage"``): a plan paid a terminal offset hundreds of times over, so it
bought e_N ≈ 0 with swings and loops, and a competitor's mean cost was below revision 4's
on 10 of the 47 default scenarios (``esso_osaka_nominal`` 180.8 against ``pid_los``'s
88.7).  Measured against it on those scenarios' 100 trials, all three held wrongly: the
heading alone, w_ψ|ψ̃_N| held (a parallel offset on ``mariner_track`` never closed: 1094
and 1349 on its smoke trials against 626 and 619), and the approach term plus the cost of
closing the offset at the look-ahead, [(Δ + w_ψL)|e_N|/L + (e_N/L)²L/2]/(U·Ts)
(``esso_osaka_nominal`` 190.2: the closing cost measured to the leg before a switch the
prediction had not yet made pulled the turn out wide).

**Horizon rule.**  H = 2(T + (L + R0)/U) + δmax/δ̇max: two of the ship's yaw time constants T
(its first-order Nomoto T of the nominal model, the one the classical controllers use) to
settle a turn; twice the time to cross one ship length plus the acceptance radius R0 of a
waypoint route (0 on a PCHIP route), so that the prediction sees past a leg switch, where
the env's cross-track error jumps to the next leg (shorter horizons were measured to
avoid the acceptance circle on nomoto2 and miss the goal); plus the time the rudder needs
to travel its range at its rate limit (0 without a rate limit).  Catalogue values:
nomoto2 10.0 s (21 steps of 0.5 s), Esso Osaka (1:100) 32 s on its curved route, Mariner
268 s on its waypoint route, Blanke 51 s.

**Decisions and grid.**  Move blocking: the first command acts for one control period Ts
(the one applied); the P = ⌈H/Ts − 1⌉ control periods after it are split into ``blocks``
= B intervals, one command each, that grow geometrically (revision 3): ⌊min(r^j, T/Ts)⌋
periods, j = 0 … B − 1, the first one period long and none longer than the ship's yaw time
constant T (at least ⌈(P − 1)/(B − 1)⌉), r ≥ 1 chosen so that they fill P (the periods lost to the
rounding go one each to the last intervals).  Reason: the plan is applied one period at a
time and re-planned, so the near commands decide what the ship does (the rudder's rate
limit and the turn's onset act within seconds), while far ahead only where the ship
settles matters, and a command interval longer than T no longer resolves a turn.
Catalogue grids (command intervals in periods): nomoto2 21 × 1 (P ≤ B: unchanged); the
Mariner on ``mariner_track`` (Ts = 1 s, T = 44 s, P = 267) 1, 1, 1, 1, 1, 2, 2, 3, 4,
5, 6, 8, 9, 13, 16, 19, 24, 29, 35, 44, 44 (revision 2: 1 then 20 × 14); Blanke (Ts =
0.2 s, T = 2.9 s, P = 256) 1, 1, 1, 3, 13, fifteen 14, 15 (revision 2: 1 then 20 × 13); Esso
Osaka on a waypoint route (Ts = 0.5 s, T = 7.4 s, P = 127) 1 × 6, 2, 2, 3, 3, … 14, 15,
15, 15.  Measured (quick suite's Mariner trials and ``mariner_track``'s smoke seeds,
scenario means): revision 2's equal intervals of 12–14 s cost 330, 193, 163 and 1180 on
``mariner_rudder_aging``, ``_current_shift``, ``_maneuverability_change`` and
``mariner_track``; the geometric ones 193, 108, 121 and 578, all below the tuned
``pid_los`` (368, 193, 177, 734), at the same solve time; uncapped (the last interval 3.4 T
on Blanke) ``blanke_rudder_aging`` cost 244 against 179 before, capped 161.  The stage
cost is evaluated at every control step end, as the env does.  Prediction step h_p = Ts/n
with n the smallest integer such that h_p·|λ_max| ≤ 2 (λ_max the fastest eigenvalue of the
nominal model linearised at cruise; RK4 is stable to 2.79 on the negative real axis), never
finer than the env's own h.

**Solver.**  Generalised Gauss–Newton SQP (Messerer, Baumgärtner & Diehl 2021): the cost
is Σ φ_i(z_i(u)) with convex outer φ (smooth |·| or square) of a smooth inner z; each
iteration solves the box QP with H = Jᵀ diag(c) J, g = Jᵀ φ' (:class:`BoxQP`), c = φ'' for
the squares and the curvature 1/√(z² + ε²) of the quadratic majoriser for the smooth |·|
(iteratively reweighted least squares: φ'' itself vanishes away from 0), then a
backtracking line search on the cost; stopped when an iteration gains less than
``cost_tolerance`` (relative) or moves less than ``step_tolerance``; warm-started from the
previous plan shifted by one control period (:func:`shifted_plan`; revisions 1–2 shifted it
by one interval but kept the first command, one period off on nomoto2's one-period
intervals: on the agile, yaw-unstable nomoto2 after its manoeuvrability jump that start
sent the SQP to a spin, 17 of the first 20 default ``maneuverability_change`` /
``_long`` trials lost to the time limit, all 20 reached with the true shift).
**Multiple starts**: the objective is not convex in the turn's direction (left and right
round a corner, or a U-turn back onto the path, are separate basins the local SQP does
not leave), so when the warm start's plan ends the horizon heading backwards along the
path (|ψ̃_N| > ``reverse_heading`` = π/2) the step also solves from the cheaper (by the
objective) of two hard-turn starts, full rudder to either side
over the whole horizon (``turn_fraction``), and keeps the plan of lower objective.
Measured: with the tail alone 9 of the 16 lost nomoto2 path-1 trials (nominal,
rudder_aging, current_shift) were still lost, by turns the warm start could not undo;
half-horizon turn starts could not reach a U-turn within nomoto2's 10 s horizon; turn
starts at every step (not only when the plan ends backwards) lost 7 maneuverability_change
trials (spins of the agile ship after its jump) and esso_osaka_nominal seed 10000, at
twice the solve time.  z and J = ∂z/∂u come from one CasADi function compiled to C
(cached, :mod:`shipgym.codegen`): the horizon is a ``mapaccum`` loop, and J is carried as
forward sensitivities S = ∂x/∂u (S⁺ = A·S + B·e_jᵀ, A and B of one period in closed form),
so the generated code stays small for horizons of hundreds of steps.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import time
from typing import Any, ClassVar

import casadi as ca
import numpy as np

from shipgym.codegen import compiled_all
from shipgym.envs.context import ControllerContext
from shipgym.envs.truth import PlantTruth
from shipgym.identification.nominal import first_order_nomoto
from shipgym.models.base import ShipModel
from shipgym_baselines.classical.box_qp import BoxQP, bind, sqp
from shipgym_baselines.errors import ControllerError

#: revision of the oracle's rules (horizon, grid, path model): reference data computed with
#: the oracle is valid for one revision; bump it whenever a change moves its numbers
ORACLE_REVISION = 5
#: the tail's speed rules (module doc, "Tail")
TAIL_SPEEDS = ("measured", "cruise")
#: what the tail prices at the horizon's end (module doc, "Tail")
TAIL_TERMS = ("approach", "stage")
#: how the prediction holds the wave load (module doc, "Model")
WAVE_FORECASTS = ("mean", "held")


@dataclasses.dataclass(frozen=True)
class OracleSettings:
    """Numerical choices of the oracle (module doc); the objective is the env's."""

    horizon_factor: float = 2.0  # k in H = k(T + (L + R0)/U) + δmax/δ̇max
    blocks: int = 20  # command intervals after the first (move blocking)
    geometric_blocks: bool = True  # intervals growing geometrically from one period (rev. 3)
    legs: int = 4  # path segments ahead in the prediction
    smooth_abs: float = 1e-3  # ε of √(z² + ε²) on e/L and ψ̃ [rad]
    switch_width_L: float = 0.1  # width of the smooth leg switch [L]
    turn_fraction: float = 1.0  # share of the intervals at full rudder in a hard-turn start
    reverse_heading: float = math.pi / 2  # rad: |ψ̃| at the horizon's end that calls the turns
    max_iter: int = 10  # generalised Gauss–Newton iterations per control step
    step_tolerance: float = 1e-4  # rad: stop when the accepted step is smaller
    cost_tolerance: float = 1e-3  # stop when an iteration lowers the cost by less (relative)
    tail_speed: str = "measured"  # U of the tail: the true speed now ("cruise": revisions 1–3)
    tail_terms: str = "approach"  # the tail's terms (module doc; "stage": revisions 2–4)
    approach_L: float = 2.0  # Δ [L]: the look-ahead of the tail's approach to the path
    wave_forecast: str = "mean"  # the wave load after the applied period ("held": revision 4)
    compile: bool = True  # compile z and its Jacobian to C (cached); VM otherwise


@dataclasses.dataclass(frozen=True)
class OracleGrid:
    """The time grid of one ship's prediction (module doc), all in control periods Ts."""

    horizon_s: float  # H [s]
    lengths: tuple[int, ...]  # control periods of each command interval (the first: 1)
    substeps: int  # RK4 steps per control period (h_p = Ts / substeps)

    @property
    def steps(self) -> int:
        """Control steps in the horizon."""
        return sum(self.lengths)

    @property
    def blocks(self) -> int:
        """Command intervals after the first."""
        return len(self.lengths) - 1


def _geometric_sum(r: float, blocks: int, cap: float) -> float:
    return sum(min(r**j, cap) for j in range(blocks))


def growth_ratio(periods: int, blocks: int, cap: float = math.inf) -> float:
    """r ≥ 1 with Σ_{j<blocks} min(r^j, cap) = ``periods`` (bisection): the ratio of the
    geometric intervals, the first one period long and none longer than ``cap`` periods,
    that fill ``periods`` control periods with ``blocks`` intervals; 1 when ``periods`` ≤
    ``blocks``.  Needs 1 + cap·(blocks − 1) ≥ periods (the sum's limit as r grows)."""
    if periods <= blocks:
        return 1.0
    if 1.0 + cap * (blocks - 1) < periods:
        raise ValueError(f"{blocks} intervals of at most {cap} periods cannot fill {periods}")
    lo, hi = 1.0, 2.0
    while _geometric_sum(hi, blocks, cap) < periods:
        lo, hi = hi, 2.0 * hi
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if _geometric_sum(mid, blocks, cap) < periods else (lo, mid)
    return hi


def block_lengths(
    periods: int, blocks: int, longest: float = math.inf, geometric: bool = True
) -> tuple[int, ...]:
    """Control periods of the command intervals of a horizon of ``periods`` + 1 steps: the
    applied command (1), then ``blocks`` intervals (module doc, "Decisions and grid").
    ``geometric``: the intervals ⌊min(r^j, cap)⌋, j = 0 … blocks − 1, with the cap
    max(⌊``longest``⌋, ⌈(periods − 1)/(blocks − 1)⌉) and r from :func:`growth_ratio`, the
    periods lost to the rounding added one each to the last intervals (one period first,
    non-decreasing, the total exactly ``periods``); otherwise ``blocks`` equal intervals of
    ⌈periods/blocks⌉ (revisions 1–2).  ``periods`` ≤ ``blocks``: ``blocks`` intervals of one
    period."""
    if periods <= blocks:
        return (1,) * (1 + blocks)
    if not geometric:
        return (1,) + (math.ceil(periods / blocks),) * blocks
    # at least the cap that one period and blocks − 1 capped intervals need to fill P
    cap = max(float(math.floor(longest)), float(math.ceil((periods - 1) / (blocks - 1))))
    r = growth_ratio(periods, blocks, cap)
    lengths = [math.floor(min(r**j, cap) + 1e-9) for j in range(blocks)]
    short = periods - sum(lengths)  # < blocks: one more period to each of the last ones
    return (1, *(n + (j >= blocks - short) for j, n in enumerate(lengths)))


def horizon_seconds(
    time_constant: float,
    length: float,
    speed: float,
    limit: float,
    rate: float,
    acceptance_radius: float,
    k: float = 2.0,
) -> float:
    """H = k(T + (L + R0)/U) + δmax/δ̇max [s] (module doc); T [s], L [m], U [m/s], δmax
    [rad], δ̇max [rad/s] (inf: no rate limit), R0 [m] the acceptance radius."""
    travel = limit / rate if math.isfinite(rate) and rate > 0 else 0.0
    return k * (time_constant + (length + acceptance_radius) / speed) + travel


def prediction_substeps(model: ShipModel, control_period: float, fine_step: float) -> int:
    """n: RK4 steps per control period, the smallest with (Ts/n)·|λ_max| ≤ 2 at cruise (RK4
    is stable to 2.79 on the negative real axis), at most Ts/h (never finer than the env's
    own step)."""
    x = ca.SX.sym("x", model.n_states)
    jac = ca.Function(
        "a", [x], [ca.jacobian(model.casadi_rhs(x, 0.0, 0.0, model.params.to_vector()), x)]
    )
    a = np.array(jac(model.cruise_state()))
    fastest = float(np.max(np.abs(np.linalg.eigvals(a)))) if a.size else 0.0
    most = max(1, round(control_period / fine_step))
    return int(min(most, max(1, math.ceil(0.5 * control_period * fastest - 1e-9))))


def oracle_grid(context: ControllerContext, settings: OracleSettings) -> OracleGrid:
    """The grid of ``context``'s ship (module doc), from its nominal model."""
    model = context.nominal_model
    _, time_constant = first_order_nomoto(model, context.nominal_params)
    h = horizon_seconds(
        time_constant,
        context.ship_length,
        context.nominal_speed,
        context.rudder_limit,
        model.rudder_rate_limit,
        context.acceptance_radius if context.path_type == "waypoints" else 0.0,
        settings.horizon_factor,
    )
    ts = context.control_period
    periods = max(1, math.ceil(h / ts - 1.0 - 1e-9))  # control periods after the first
    lengths = block_lengths(periods, settings.blocks, time_constant / ts, settings.geometric_blocks)
    substeps = prediction_substeps(model, ts, context.fine_step)
    return OracleGrid(horizon_s=h, lengths=lengths, substeps=substeps)


def _smooth_step(z: Any) -> Any:
    return 0.5 * (1.0 + ca.tanh(z))


#: layout of one leg in the solver's parameters: start (x0, y0), unit direction (c, s), ℓ
LEG_SIZE = 5


def _geometry(model: ShipModel, x: Any, legs: Any, j: int) -> tuple[Any, Any, Any]:
    """(along-track [m], cross-track e [m], ψ̃ [rad]) of state ``x`` on leg ``j``."""
    x0, y0, c, s, _ = (legs[LEG_SIZE * j + i] for i in range(LEG_SIZE))
    rx, ry = x[model.state_index("x")] - x0, x[model.state_index("y")] - y0
    psi = x[model.state_index("psi")]
    heading = ca.atan2(ca.sin(psi) * c - ca.cos(psi) * s, ca.cos(psi) * c + ca.sin(psi) * s)
    return rx * c + ry * s, -rx * s + ry * c, heading


def _period_function(
    model: ShipModel, hp: float, substeps: int, n_legs: int, width: float
) -> ca.Function:
    """(x, q, u, w, θ, legs, R0, circle) -> (x, q) one control period later: ``substeps`` RK4
    steps of h_p [s] with u, w, θ held, then the leg latches q_j ∈ [0, 1] ("leg j is done")
    updated at the period's end as the env's tracker switches legs:
    q_j⁺ = q_j + (1 − q_j)·σ_j, σ_j the smooth switching rule of leg j (``circle`` = 1: inside
    the acceptance circle R0 of its end, Liu eq. (13); 0: along-track past ℓ − R0, Borkowski
    eq. (27)), over ``width`` [m].  The latches make a switch permanent, as in the env."""
    step = model.casadi_step(hp)
    x = ca.SX.sym("x", model.n_states)
    q = ca.SX.sym("q", n_legs - 1)
    u = ca.SX.sym("u")
    w = ca.SX.sym("w", model.n_disturbances)
    theta = ca.SX.sym("theta", model.n_params)
    legs = ca.SX.sym("legs", LEG_SIZE * n_legs)
    radius = ca.SX.sym("R0")
    circle = ca.SX.sym("circle")
    xk = x
    for _ in range(substeps):
        xk = step(xk, u, w, theta)
    latches = []
    for j in range(n_legs - 1):
        along, cross, _ = _geometry(model, xk, legs, j)
        ell = legs[LEG_SIZE * j + 4]
        # 2·width inside the rule's edge: the prediction switches only where the env surely does
        inside = _smooth_step((radius - ca.sqrt((along - ell) ** 2 + cross**2)) / width - 2.0)
        past = _smooth_step((along - (ell - radius)) / width - 2.0)
        latches.append(q[j] + (1.0 - q[j]) * (circle * inside + (1.0 - circle) * past))
    xa = ca.vertcat(x, q)
    xa_next = ca.vertcat(xk, *latches)
    return ca.Function("oracle_period", [xa, u, w, theta, legs, radius, circle], [xa_next])


def _stage_function(model: ShipModel, n_legs: int, length: float) -> ca.Function:
    """[e/L, ψ̃ [rad]] of an augmented state (x, q) to its active leg: leg j weighs
    q_0⋯q_{j−1}(1 − q_j) (the last leg q_0⋯q_{K−2})."""
    xa = ca.SX.sym("xa", model.n_states + n_legs - 1)
    legs = ca.SX.sym("legs", LEG_SIZE * n_legs)
    q = xa[model.n_states :]
    e_sum, h_sum = 0.0, 0.0
    reached = 1.0
    for j in range(n_legs):
        _, cross, heading = _geometry(model, xa, legs, j)
        weight = reached if j == n_legs - 1 else reached * (1.0 - q[j])
        if j < n_legs - 1:
            reached = reached * q[j]
        e_sum += weight * cross
        h_sum += weight * heading
    return ca.Function("oracle_stage", [xa, legs], [ca.vertcat(e_sum / length, h_sum)])


def _approach_function(model: ShipModel, n_legs: int, lookahead: float) -> ca.Function:
    """(xa_{N−1}, xa_N, legs) -> χ̃_N + atan(e_N/Δ) [rad]: how far the course over ground
    over the horizon's last control period (the displacement's direction, to the active
    leg) is from the course that closes the cross-track error e_N at the look-ahead
    Δ = ``lookahead`` [m] (the approach of a look-ahead LOS guidance), weighted over the
    legs as :func:`_stage_function` weighs them."""
    nxa = model.n_states + n_legs - 1
    before, after = ca.SX.sym("xa0", nxa), ca.SX.sym("xa1", nxa)
    legs = ca.SX.sym("legs", LEG_SIZE * n_legs)
    q = after[model.n_states :]
    ix, iy = model.state_index("x"), model.state_index("y")
    dx, dy = after[ix] - before[ix], after[iy] - before[iy]
    total, reached = 0.0, 1.0
    for j in range(n_legs):
        _, cross, _ = _geometry(model, after, legs, j)
        c, s = legs[LEG_SIZE * j + 2], legs[LEG_SIZE * j + 3]
        course = ca.atan2(dy * c - dx * s, dx * c + dy * s)
        weight = reached if j == n_legs - 1 else reached * (1.0 - q[j])
        if j < n_legs - 1:
            reached = reached * q[j]
        total += weight * (course + ca.atan(cross / lookahead))
    return ca.Function("oracle_approach", [before, after, legs], [total])


def _sensitivity_function(period: ca.Function, n_u: int) -> ca.Function:
    """(x, S, u, …, e) -> (x⁺, A·S + B·eᵀ): one period with the forward sensitivity
    S = ∂x/∂(plan) [n × n_u]; A = ∂x⁺/∂x, B = ∂x⁺/∂u, e the one-hot of the step's interval;
    the other inputs pass through to ``period``."""
    n = period.size1_in(0)
    x = ca.SX.sym("x", n)
    sens = ca.SX.sym("S", n, n_u)
    u = ca.SX.sym("u")
    rest = [ca.SX.sym(f"a{i}", period.size1_in(i)) for i in range(2, period.n_in())]
    onehot = ca.SX.sym("e", n_u)
    xn = period(x, u, *rest)
    a, b = ca.jacobian(xn, x), ca.jacobian(xn, u)
    return ca.Function(
        "oracle_period_s", [x, sens, u, *rest, onehot], [xn, a @ sens + b @ onehot.T]
    )


def _stage_jacobian_function(stage: ca.Function, n_u: int) -> ca.Function:
    """(x, S, legs) -> (g(x), ∂g/∂x · S): the stage errors and their plan derivatives."""
    x = ca.SX.sym("x", stage.size1_in(0))
    sens = ca.SX.sym("S", stage.size1_in(0), n_u)
    legs = ca.SX.sym("legs", stage.size1_in(1))
    g = stage(x, legs)
    return ca.Function("oracle_stage_s", [x, sens, legs], [g, ca.jacobian(g, x) @ sens])


def _approach_jacobian_function(approach: ca.Function, n_u: int) -> ca.Function:
    """(x0, S0, x1, S1, legs) -> (a, ∂a/∂x0·S0 + ∂a/∂x1·S1): the approach residual of
    :func:`_approach_function` and its plan derivative."""
    n = approach.size1_in(0)
    x0, x1 = ca.SX.sym("x0", n), ca.SX.sym("x1", n)
    s0, s1 = ca.SX.sym("S0", n, n_u), ca.SX.sym("S1", n, n_u)
    legs = ca.SX.sym("legs", approach.size1_in(2))
    a = approach(x0, x1, legs)
    d = ca.jacobian(a, x0) @ s0 + ca.jacobian(a, x1) @ s1
    return ca.Function("oracle_approach_s", [x0, s0, x1, s1, legs], [a, d])


class OracleSolver:
    """The oracle's problem for one model class, grid, timing and reward weights (built
    once per process): inner residuals z(u; p) and J = ∂z/∂u, the outer φ, the GGN SQP."""

    def __init__(
        self,
        model: ShipModel,
        grid: OracleGrid,
        settings: OracleSettings,
        control_period: float,
        rudder_limit: float,
        weights: tuple[float, float, float],
        length: float,
    ) -> None:
        s = settings
        self.grid, self.settings = grid, settings
        self.rudder_limit = rudder_limit
        nx, npar, nw = model.n_states, model.n_params, model.n_disturbances
        n_u = 1 + grid.blocks
        n_legs = s.legs
        period = _period_function(
            model, control_period / grid.substeps, grid.substeps, n_legs, s.switch_width_L * length
        )
        stage = _stage_function(model, n_legs, length)
        steps = grid.steps
        interval = [j for j, n in enumerate(grid.lengths) for _ in range(n)]  # per step
        u = ca.MX.sym("u", n_u)
        # parameters: x0, δc_prev, R0, circle rule (1/0), legs (x0, y0, c, s, ℓ) each, θ, w
        # per interval
        n_p = nx + 3 + LEG_SIZE * n_legs + npar + nw * n_u
        p = ca.MX.sym("p", n_p)
        x0, u_prev, radius, circle = p[:nx], p[nx], p[nx + 1], p[nx + 2]
        i_legs = nx + 3
        i_theta = i_legs + LEG_SIZE * n_legs
        legs = p[i_legs:i_theta]
        theta = p[i_theta : i_theta + npar]
        w_all = ca.reshape(p[i_theta + npar :], nw, n_u)
        xa0 = ca.vertcat(x0, ca.DM.zeros(n_legs - 1))  # no leg done at the start
        # the control steps of the horizon in one C loop (mapaccum), their errors mapped;
        # J by forward sensitivities S = ∂x/∂u carried along (S⁺ = A·S + B·e_jᵀ)
        inputs = (
            u[interval].T,
            w_all[:, interval],
            ca.repmat(theta, 1, steps),
            ca.repmat(legs, 1, steps),
            ca.repmat(radius, 1, steps),
            ca.repmat(circle, 1, steps),
        )
        onehot = ca.DM.zeros(n_u, steps)
        for k, j in enumerate(interval):
            onehot[j, k] = 1.0
        states = period.mapaccum("roll", steps)(xa0, *inputs)
        errors = stage.map(steps)(states, ca.repmat(legs, 1, steps))
        states_s, sens = _sensitivity_function(period, n_u).mapaccum("roll_s", steps, 2)(
            xa0, ca.DM.zeros(xa0.shape[0], n_u), *inputs, onehot
        )
        errors_s, d_errors = _stage_jacobian_function(stage, n_u).map(steps)(
            states_s, sens, ca.repmat(legs, 1, steps)
        )
        z_u = u / rudder_limit
        z_du = ca.vertcat(u[0] - u_prev, u[1:] - u[:-1]) / rudder_limit
        # the tail's residual (module doc, "Tail"): the approach χ̃_N + atan(e_N/Δ), from
        # the horizon's last control period
        approach = _approach_function(model, n_legs, s.approach_L * length)
        last = [xa0, states[:, 0]] if steps == 1 else [states[:, -2], states[:, -1]]
        z_app = approach(*last, legs)
        sens_of = [sens[:, k * n_u : (k + 1) * n_u] for k in range(max(0, steps - 2), steps)]
        last_s = (
            [xa0, ca.DM.zeros(xa0.shape[0], n_u), states_s[:, 0], sens_of[-1]]
            if steps == 1
            else [states_s[:, -2], sens_of[0], states_s[:, -1], sens_of[1]]
        )
        z_app_s, d_app = _approach_jacobian_function(approach, n_u)(*last_s, legs)
        z = ca.vertcat(errors[0, :].T, errors[1, :].T, z_u, z_du, z_app)
        z_s = ca.vertcat(errors_s[0, :].T, errors_s[1, :].T, z_u, z_du, z_app_s)
        eye = np.eye(n_u) / rudder_limit
        diff = (np.eye(n_u) - np.eye(n_u, k=-1)) / rudder_limit
        jac = ca.vertcat(
            ca.reshape(d_errors[0, :], n_u, steps).T,
            ca.reshape(d_errors[1, :], n_u, steps).T,
            eye,
            diff,
            d_app,
        )
        w_psi, w_delta, w_rate = weights
        # outer weights and kinds: smooth |·| for e/L and ψ̃, squares for the rudder terms
        self.weight = np.concatenate(
            [
                np.ones(steps),
                np.full(steps, w_psi),
                w_delta * np.array(grid.lengths, dtype=float),
                np.full(n_u, w_rate),
                [0.0],  # the tail's approach residual: weighed by set_tail
            ]
        )
        self.is_abs = np.concatenate([np.ones(2 * steps, bool), np.zeros(2 * n_u, bool), [True]])
        self._base_weight = self.weight.copy()
        self._terminal = np.array([steps - 1, 2 * steps - 1])  # e/L and ψ̃ at the horizon's end
        self._approach = self.weight.size - 1
        self._w_psi = w_psi
        self.n_z, self.n_u, self.n_p = z.shape[0], n_u, n_p
        key = (control_period, rudder_limit, weights, length, s.switch_width_L, grid.lengths)
        tag = (
            f"{model.name}_b{grid.blocks}x{grid.steps}_s{grid.substeps}_l{n_legs}"
            f"_{abs(hash(key)) % 10**8}"
        )
        value = ca.Function(f"oracle_z_{tag}", [u, p], [z])
        both = ca.Function(f"oracle_zj_{tag}", [u, p], [z_s, ca.densify(jac)])
        if s.compile:
            value, both = compiled_all([value, both], what=f"the oracle's {model.name} solver")
        self._u = np.zeros(n_u)
        self._p = np.zeros(n_p)
        self._fresh = False  # whether _z is the value function's at (_u, _p)
        self._z = np.zeros(self.n_z)
        self._j = np.zeros((n_u, self.n_z))  # column-major J
        self._value = bind(value, [self._u, self._p], [self._z])
        self._both = bind(both, [self._u, self._p], [self._z, self._j])
        self._keep = (value, both)
        self.lb = np.full(n_u, -rudder_limit)
        self.ub = np.full(n_u, rudder_limit)
        self._qp = BoxQP(n_u)

    # ---------------------------------------------------------------- cost and SQP
    def _outer(self, z: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
        """Σφ(z), φ'(z), φ''(z) (weighted)."""
        eps = self.settings.smooth_abs
        root = np.sqrt(z * z + eps * eps)
        value = np.where(self.is_abs, root, z * z)
        d1 = np.where(self.is_abs, z / root, 2.0 * z)
        # |·| terms: the curvature of the quadratic majoriser at z (IRLS), 1/√(z² + ε²), not
        # φ'' = ε²/(z² + ε²)^{3/2}, which vanishes away from 0 (the steps would overshoot)
        d2 = np.where(self.is_abs, 1.0 / root, 2.0)
        w = self.weight
        with np.errstate(over="ignore", invalid="ignore"):
            total = float(w @ value)
        return (total if math.isfinite(total) else math.inf), w * d1, w * d2

    def cost(self, plan: np.ndarray, p: np.ndarray) -> float:
        """The predicted objective of ``plan`` (inf if the prediction diverges); the
        residuals stay in ``_z`` until the next evaluation."""
        if not (self._fresh and np.array_equal(plan, self._u) and np.array_equal(p, self._p)):
            self._u[:], self._p[:] = plan, p
            self._value[1]()
            self._fresh = True  # _z holds the value function's residuals at (_u, _p)
        return self._outer(self._z)[0]

    def set_tail(self, steps: float) -> None:
        """Weigh the tail (module doc, "Tail") for ``steps`` [control periods] still to go
        after the horizon: the approach residual w_ψ·N_tail (``tail_terms = "approach"``),
        or the terminal |e|/L and w_ψ|ψ̃| held N_tail steps more (``"stage"``, revisions
        2–4)."""
        self.weight = self._base_weight.copy()
        steps = max(0.0, float(steps))
        if self.settings.tail_terms == "stage":
            self.weight[self._terminal] *= 1.0 + steps
        else:
            self.weight[self._approach] = self._w_psi * steps

    def solve(
        self, p: np.ndarray, guess: np.ndarray, tail: float = 0.0
    ) -> tuple[np.ndarray, bool, int]:
        """Plan (one command per interval, rad), success flag, iterations; ``tail``: the
        control steps still to go after the horizon (:meth:`set_tail`)."""
        self._p[:] = p
        self._fresh = False  # _z was computed at another p
        self.set_tail(tail)

        def direction(u: np.ndarray) -> np.ndarray | None:
            self._fresh = False  # _z is about to hold the sensitivity function's residuals
            self._u[:] = u
            self._both[1]()
            z, jac = self._z, self._j.T
            if not (np.all(np.isfinite(z)) and np.all(np.isfinite(jac))):
                return None
            _, d1, d2 = self._outer(z)
            return self._qp.solve((jac.T * d2) @ jac, jac.T @ d1, self.lb - u, self.ub - u)

        s = self.settings
        return sqp(
            guess,
            self.lb,
            self.ub,
            lambda u: self.cost(u, p),
            direction,
            s.max_iter,
            s.step_tolerance,
            s.cost_tolerance,
        )

    def turn_guesses(self) -> list[np.ndarray]:
        """The two hard-turn starts: full rudder to one side over the first
        ``turn_fraction`` of the horizon's intervals, midships after [rad]."""
        half = np.arange(self.n_u) < max(1, round(self.settings.turn_fraction * self.n_u))
        return [np.where(half, sign * self.rudder_limit, 0.0) for sign in (1.0, -1.0)]

    def solve_multistart(
        self, p: np.ndarray, guess: np.ndarray, tail: float = 0.0
    ) -> tuple[np.ndarray, bool, int]:
        """:meth:`solve` from ``guess`` (the warm start); if its plan ends the horizon
        heading backwards along the path (|ψ̃_N| > ``reverse_heading``), also from the
        cheaper of the two hard-turn starts (:meth:`turn_guesses`), keeping the plan of
        lower objective."""
        plan, ok, total = self.solve(p, guess, tail)
        if ok:
            self.cost(plan, p)
            if abs(self._z[self._terminal[1]]) <= self.settings.reverse_heading:
                return plan, ok, total
        turn = min(self.turn_guesses(), key=lambda u: self.cost(u, p))
        other, other_ok, iterations = self.solve(p, turn, tail)
        total += iterations
        if other_ok and (not ok or self.cost(other, p) < self.cost(plan, p)):
            return other, True, total
        return plan, ok, total

    def parameters(
        self,
        state: np.ndarray,
        previous_command: float,
        switch_radius: float,
        circle: bool,
        legs: np.ndarray,
        theta: np.ndarray,
        disturbances: np.ndarray,
    ) -> np.ndarray:
        """The solver's parameter vector; ``legs`` (legs, 5) rows (x0, y0, c, s, ℓ),
        ``disturbances`` (intervals, n_w)."""
        return np.concatenate(
            [
                state,
                [previous_command, switch_radius, float(circle)],
                legs.ravel(),
                theta,
                disturbances.ravel(),
            ]
        )


_SOLVERS: dict[tuple, OracleSolver] = {}


def get_solver(context: ControllerContext, settings: OracleSettings, weights) -> OracleSolver:
    """One solver per process for a ship class, grid, timing and reward weights."""
    grid = oracle_grid(context, settings)
    model = context.nominal_model
    key = (
        type(model).__name__,
        model.variant,
        context.ship_length,
        grid,
        settings,
        context.control_period,
        context.rudder_limit,
        weights,
    )
    if key not in _SOLVERS:
        _SOLVERS[key] = OracleSolver(
            model,
            grid,
            settings,
            context.control_period,
            context.rudder_limit,
            weights,
            context.ship_length,
        )
    return _SOLVERS[key]


def _curve_point(path: Any, s: float) -> np.ndarray:
    """The point at arc length s [m] of a PCHIP route, continued along its final tangent
    past the end."""
    if s <= path.length:
        return np.asarray(path.point(s), dtype=float)
    angle = float(path.angle(path.length))
    end = np.asarray(path.point(path.length), dtype=float)
    return end + (s - path.length) * np.array([math.cos(angle), math.sin(angle)])


def _leg_row(a: np.ndarray, b: np.ndarray, length: float | None = None) -> list[float]:
    """(x0, y0, c, s, ℓ) of the segment a → b [m] (ℓ overridden by ``length``)."""
    d = b - a
    ell = float(np.hypot(*d))
    return [a[0], a[1], d[0] / ell, d[1] / ell, ell if length is None else length]


#: the length given to the last leg of a route: the env never leaves it
LAST_LEG = 1e6


def legs_ahead(
    context: ControllerContext, tracker: Any, frame: Any, horizon_m: float, n: int
) -> tuple[np.ndarray, float]:
    """(n, 5) legs (x0, y0, c, s, ℓ) from the active one on, and the switching radius [m]:
    the waypoint legs (the last one never left) with the acceptance radius, or the chords of
    a PCHIP route over 1.3 horizons ahead of the closest point, switched at their ends."""
    if tracker.is_curve:
        ds = 1.3 * horizon_m / n
        s0 = float(frame.along_track)
        points = [_curve_point(tracker.path, s0 + i * ds) for i in range(n + 1)]
        return np.array([_leg_row(a, b) for a, b in itertools.pairwise(points)]), 0.0
    wp = np.asarray(context.waypoints, dtype=float)
    last = len(wp) - 2
    rows = []
    for j in range(int(frame.leg), int(frame.leg) + n):
        i = min(j, last)
        rows.append(_leg_row(wp[i], wp[i + 1], LAST_LEG if i == last else None))
    return np.array(rows), context.acceptance_radius


def remaining_path(context: ControllerContext, tracker: Any, frame: Any) -> float:
    """The path still to go to the goal [m] from the tracker's point: the rest of the active
    leg and the legs after it, or the arc length left on a PCHIP route."""
    if tracker.is_curve:
        return max(0.0, float(tracker.path.length) - float(frame.along_track))
    wp = np.asarray(context.waypoints, dtype=float)
    lengths = np.hypot(*np.diff(wp, axis=0).T)
    leg = int(frame.leg)
    return max(0.0, float(lengths[leg]) - float(frame.along_track)) + float(
        lengths[leg + 1 :].sum()
    )


def tail_steps(
    remaining_m: float, speed: float, control_period: float, horizon_steps: int
) -> float:
    """The control steps still to go after the horizon [-]: the time to cover the remaining
    path [m] at speed U [m/s] (:func:`tail_speed`), less the horizon's steps, at least 0."""
    return max(0.0, remaining_m / (speed * control_period) - horizon_steps)


def shifted_plan(plan: np.ndarray, lengths: tuple[int, ...]) -> np.ndarray:
    """The warm start: ``plan`` [rad, one command per interval of ``lengths`` control
    periods] one control period later, its last command held, each interval given the mean
    of the shifted commands it covers (exact for intervals of one period)."""
    per_step = np.repeat(plan, lengths)
    shifted = np.append(per_step[1:], per_step[-1])
    edges = np.cumsum((0, *lengths))
    return np.add.reduceat(shifted, edges[:-1]) / np.asarray(lengths, dtype=float)


def speed_over_ground(model: ShipModel, truth: PlantTruth, command: float) -> float:
    """The true speed over ground now [m/s]: |(ẋ, ẏ)| of the model's right-hand side at
    the true state, parameters and disturbances, with the rudder command ``command`` [rad]."""
    xdot = np.asarray(
        model.casadi_rhs(truth.state, command, truth.disturbance_now, truth.params.to_vector())
    ).ravel()
    return float(np.hypot(xdot[model.state_index("x")], xdot[model.state_index("y")]))


def tail_speed(
    settings: OracleSettings, model: ShipModel, truth: PlantTruth, command: float, cruise: float
) -> float:
    """U of the tail [m/s] (module doc): the true speed over ground now, at least half the
    cruise speed ``cruise`` (``tail_speed = "measured"``), or the cruise speed itself."""
    if settings.tail_speed == "cruise":
        return cruise
    return max(0.5 * cruise, speed_over_ground(model, truth, command))


def predicted_disturbances(
    settings: OracleSettings, plant: PlantTruth, intervals: int
) -> np.ndarray:
    """(intervals, n_w) the disturbances the prediction holds over each command interval
    (module doc, "Model"): those acting now over the applied one; after it the current and
    the yaw bias as they act now and the wave load at its mean, 0 (``wave_forecast =
    "mean"``), or the wave load now too (``"held"``, revision 4)."""
    rows = np.tile(plant.disturbance_now, (intervals, 1))
    if settings.wave_forecast == "mean":
        rows[1:] = plant.without_waves
    return rows


#: the solver of the rows that steer with the oracle's NMPC on an estimated plant
#: (``nmpc_ekf``, ``nmpc_learned_id``): one generalised Gauss–Newton iteration a control step
#: from the shifted plan, with its line search (a real-time iteration, Diehl, Bock &
#: Schlöder 2005), the oracle's cost, horizon and tail.  Measured with ``nmpc_ekf`` on the
#: 32 validation trials (8 a ship): cost over the oracle's 1.005 (geometric mean) against
#: 0.997 with the oracle's ten iterations, at 60 % of the CPU time.
REAL_TIME_SETTINGS = OracleSettings(max_iter=1)


class PlantNMPC:
    """The oracle's NMPC (module doc) on a plant handed to it at every step: the truth for
    the references, an estimate for a controller that estimates the plant
    (``nmpc_ekf``).  :meth:`start` at an episode's start, :meth:`steer` at every step.
    ``settings`` None: the class's :attr:`default_settings`."""

    name: ClassVar[str]  # each subclass's own: its name in the registry
    #: the settings of a construction without any (the references': the oracle's own)
    default_settings: ClassVar[OracleSettings] = OracleSettings()

    def __init__(self, settings: OracleSettings | None = None) -> None:
        self.settings = settings if settings is not None else self.default_settings
        for field, allowed in (
            ("tail_speed", TAIL_SPEEDS),
            ("tail_terms", TAIL_TERMS),
            ("wave_forecast", WAVE_FORECASTS),
        ):
            if getattr(self.settings, field) not in allowed:
                raise ValueError(
                    f"{field} must be one of {allowed}, got {getattr(self.settings, field)!r}"
                )

    def start(self, context: ControllerContext) -> None:
        """An episode's start: the solver of ``context``'s ship, a new tracker, no plan."""
        self.ctx = context
        reward = context.reward
        self.weights = (reward.heading_weight, reward.rudder_weight, reward.rudder_rate_weight)
        self.solver = get_solver(context, self.settings, self.weights)
        self.tracker = context.new_tracker()
        self._started = False
        self.plan = np.zeros(self.solver.n_u)
        self.command = 0.0
        self.failures = 0
        self.solve_times: list[float] = []  # wall clock [s]
        self.solve_cpu_times: list[float] = []  # this thread's CPU time [s]
        #: a whole step's times (estimate and solve) of a controller that estimates the
        #: plant: from :meth:`mark` to the end of :meth:`steer` [s]
        self.step_times: list[float] = []
        self.step_cpu_times: list[float] = []
        self._mark: tuple[float, float] | None = None

    def mark(self) -> None:
        """The start of a step whose whole time :meth:`steer` records (``step_times``)."""
        self._mark = (time.perf_counter(), time.thread_time())

    def steer(self, plant: PlantTruth) -> np.ndarray:
        """The action of one step: the plan's first command over the horizon predicted
        with ``plant``'s state, parameters and disturbances now (module doc)."""
        ctx, grid = self.ctx, self.solver.grid
        model = ctx.nominal_model
        px = float(plant.state[model.state_index("x")])
        py = float(plant.state[model.state_index("y")])
        frame = self.tracker.update(px, py) if self._started else self.tracker.reset(px, py)
        self._started = True
        legs, radius = legs_ahead(
            ctx, self.tracker, frame, grid.horizon_s * ctx.nominal_speed, self.settings.legs
        )
        p = self.solver.parameters(
            plant.state,
            self.command,
            radius,
            ctx.switching == "circle" and not self.tracker.is_curve,
            legs,
            plant.params.to_vector(),
            predicted_disturbances(self.settings, plant, self.solver.n_u),
        )
        guess = shifted_plan(self.plan, grid.lengths)
        start, cpu = time.perf_counter(), time.thread_time()
        speed = tail_speed(self.settings, model, plant, self.command, ctx.nominal_speed)
        tail = tail_steps(
            remaining_path(ctx, self.tracker, frame), speed, ctx.control_period, grid.steps
        )
        plan, ok, _ = self.solver.solve_multistart(p, guess, tail)
        self.solve_times.append(time.perf_counter() - start)
        self.solve_cpu_times.append(time.thread_time() - cpu)  # not inflated by a busy machine
        if ok:
            self.plan = plan
        else:
            self.failures += 1
            self.plan = np.clip(guess, self.solver.lb, self.solver.ub)
        self.command = float(self.plan[0])
        if self._mark is not None:
            self.step_times.append(time.perf_counter() - self._mark[0])
            self.step_cpu_times.append(time.thread_time() - self._mark[1])
            self._mark = None
        return np.array([np.clip(self.command / ctx.rudder_limit, -1.0, 1.0)], dtype=np.float32)

    def episode_stats(self) -> dict[str, float]:
        times = np.array(self.solve_times) if self.solve_times else np.array([math.nan])
        return {
            "solver_failures": float(self.failures),
            "solve_ms_median": 1e3 * float(np.median(times)),
            "solve_ms_p99": 1e3 * float(np.percentile(times, 99)),
        }


# its look (shipgym_baselines.controllers) colours its name in the page's tables; the scenario
# figures draw its episode black and dashed, the reference (shipgym_baselines.plots)
class Oracle(PlantNMPC):
    """``oracle``: NMPC on the true plant now, through the privileged channel (module doc)."""

    name: ClassVar[str] = "oracle"
    kind: ClassVar[str] = "reference"
    #: predict with the truth of the episode's start (``oracle_frozen``) instead of now
    frozen: ClassVar[bool] = False

    def __init__(self, settings: OracleSettings | None = None) -> None:
        super().__init__(settings)
        self._start: PlantTruth | None = None  # the truth at the episode's first step
        self._truth = None

    def reset(self, context: ControllerContext, seed: int | None = None) -> None:
        raise ControllerError(
            f"{self.name} reads the true plant through the evaluation loop's privileged "
            f"channel, which only the built-in references run by their own names receive; it "
            "cannot run as an instance, a spec or under another name"
        )

    def reset_privileged(
        self, context: ControllerContext, truth: Any, seed: int | None = None
    ) -> None:
        """Start an episode; ``truth()`` returns the :class:`PlantTruth` now."""
        self._truth = truth
        self._start = None  # a new episode: its first truth is captured at the first step
        self.start(context)

    def predicted_plant(self, truth: PlantTruth) -> PlantTruth:
        """The truth the prediction uses: the plant now (``oracle``), or its parameters and
        disturbances as at the episode's start with the true state now
        (``oracle_frozen``)."""
        if self._start is None:
            self._start = truth
        if not self.frozen:
            return truth
        return dataclasses.replace(
            truth,
            params=self._start.params,
            disturbance_now=self._start.disturbance_now,
            wave_now=self._start.wave_now,
        )

    def act(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        if self._truth is None:
            raise ControllerError(f"{self.name}: reset_privileged() first (the privileged channel)")
        return self.steer(self.predicted_plant(self._truth()))


class OracleFrozen(Oracle):
    """``oracle_frozen``: the oracle with its truth frozen at the episode's start (module
    doc): the optimum of a controller that never adapts."""

    name: ClassVar[str] = "oracle_frozen"
    frozen: ClassVar[bool] = True


#: the built-in references that read the true plant, by name
PRIVILEGED: dict[str, type[Oracle]] = {cls.name: cls for cls in (Oracle, OracleFrozen)}

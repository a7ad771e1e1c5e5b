"""Mariner-class ship (m.s. Compass Island), de Wit–Oppe simplified model (Borkowski, 2018).

Borkowski (2018) eq. (35) (de Wit & Oppe 1979 model with the steering gear of Fossen 1994),
in the form used here (variant ``"algebraic"``, the default)::

    ẋ = u cos ψ − v sin ψ + Vcx          ψ̇ = r
    ẏ = u sin ψ + v cos ψ + Vcy          ṙ = −a1·r − a2·r³ + a3·δ + d_yaw
    u̇ = −f·u − W·r² + S                  v = r1·r + r3·r³            (sway, algebraic)
    δ̇ = clip(clip(δz, −δmax, δmax) − δ, −δ̇max, δ̇max) / T_δ      (T_δ = 1 s: "u̇ = u_z − u")

State ``[x, y, psi, r, u, v, delta]`` (SI, rad; the seed's x1…x6 and u = δ), input δz (the
rudder command), disturbances ``[current_x, current_y, yaw_disturbance]``.  u is the
longitudinal (surge) speed V through the water (the seed's x5), v the lateral speed (x6).
ψ is measured from the x axis towards the y axis; a positive rudder angle gives a positive
yaw rate (a3 > 0), which is already the project convention: no sign flip at the boundary.

Eq. (35) as printed, and why the default differs
------------------------------------------------
The seed prints the sway line as a *differential* equation, ``ẋ6 = −r1·x4 − r3·x4³``.  Taken
literally (variant ``"printed"``) the sway speed is the integral of the yaw rate,
v = −r1·(ψ − ψ0) = 69.5 m/rad × heading change: after a 90° course change the ship slides
sideways at 109 m/s — no ship does that, and the paper's Fig. 3 shows an ordinary track.
The seed's own units settle it: r1 is given in m/rad and r3 in m·s²/rad³, so r1·r and r3·r³
are speeds [m/s], not accelerations.  Every other constant's unit fits its line as a
derivative (a1 1/s, a2 s/rad², a3 1/s², f 1/s, W m/rad², S m/s²).  Hence the default reads
the sway line as algebraic, v = r1·r + r3·r³, as ``data/ship_models.md`` §2.1 reconstructs
it.  Sign: the seed's "−r1" with r1 = −69.5 m/rad would make v and r the same sign (the ship
drifting *into* the turn, pivot point 69.5 m abaft the reference point); the data file's
"+r1" gives the outward drift of a real turning ship (pivot point 69.5 m = 0.40 L forward),
and is used.  In the default variant the state ``v`` is a read-out: it integrates
v̇ = (r1 + 3·r3·r²)·ṙ, so it equals r1·r + r3·r³ whenever it starts consistent (every state
from :meth:`Mariner.cruise_state` does), while the kinematics use r1·r + r3·r³ itself.
Variant ``"printed"`` integrates v̇ = −r1·r − r3·r³ and uses that state in the kinematics.

Checks against the paper's ship figures (Borkowski 2018 §5)
------------------------------------------------------------
* Steady turning at full rudder, ṙ = 0: a1·r + a2·r³ = a3·δ.  At δ = 0.6 rad the real root
  is r = 0.019049 rad/s (1.091 °/s), 0.27 % below the paper's r_max = 0.0191 rad/s (which
  needs δ = 0.603 rad).  Steady surge there u = (S − W·r²)/f = 4.643 m/s, drift
  v = −1.324 m/s (drift angle 15.9°), speed over ground 4.828 m/s, diameter 2U/r = 507 m
  (2.95 L).  (tests/test_mariner.py checks this through the turning-circle manoeuvre.)
* Straight-line speed: u̇ = 0 with r = 0 gives u = S/f = 7.857 m/s (15.27 kn), 2.0 % above
  the paper's initial speed 7.7 m/s (15 kn, the Mariner service speed).  The 7.7 m/s is only
  the start of the §5 run; the plant then accelerates towards S/f with time constant
  1/f = 71 s.  :meth:`Mariner.cruise_state` starts at the equilibrium S/f (so manoeuvres
  start steady); the ``mariner_track`` scenario sets u = 7.7 m/s as the paper does.
* Linear part: the paper's "nominal" Nomoto values a = 0.018 1/s, c = 0.001 1/s² (§5) are
  a1 and a3, i.e. K = a3/a1 = 0.0556 1/s, T = 1/a1 = 55.6 s.

Disturbances
------------
The model is kinematic in speed (no hydrodynamic forces of the relative velocity), so u and
v are speeds through the water and an earth-frame current (Vcx, Vcy) [m/s, flowing *to*] is
added to ẋ, ẏ: with zero speed through the water the ship drifts exactly with the current.
``yaw_disturbance`` [rad/s²] adds to ṙ; it is where the wind-wave signal of §5 enters (the
paper says only that a "signal characteristic of wind-induced sea waves" (Fossen 1994) with
the wind along the Y axis was included; its spectrum, amplitude and channel are not given).
A wave filter's ``gain`` is therefore in rad/s² per metre of filter output; a natural scale
is the rudder equivalent: a yaw acceleration d acts like the rudder angle d/a3 (a3 = 0.001
1/s², so 1° of rudder ≙ 1.75e-5 rad/s²).

Time steps
----------
The paper gives no sample time (Matlab/Simulink, 1000 s runs).  Ts = 1 s (the env's control
period) and h = 0.1 s (RK4 substep: a tenth of the 1 s steering-gear time constant, the
fastest dynamics) are our choice.
"""

from __future__ import annotations

import dataclasses
from types import SimpleNamespace
from typing import Any, ClassVar

import numpy as np

from shipgym.models.base import ParameterError, ParameterRecord, ShipModel
from shipgym.models.hull import Hull, inertia_after
from shipgym.models.ship import EnvId, Published, Ship, hull_quantities


@dataclasses.dataclass(frozen=True)
class MarinerParams(ParameterRecord):
    """de Wit–Oppe Mariner constants, SI/rad (defaults: Borkowski 2018 §5)."""

    a1: float = 0.018  # linear yaw damping [1/s]
    a2: float = 37.2  # cubic yaw damping [s/rad²]
    a3: float = 0.001  # rudder effectiveness [1/s²]
    f: float = 0.014  # surge resistance [1/s]
    W: float = 124.0  # speed loss in turns [m/rad²]
    S: float = 0.11  # propeller thrust per unit mass [m/s²]
    r1: float = -69.5  # sway from yaw rate, linear [m/rad]
    r3: float = 0.0  # sway from yaw rate, cubic [m·s²/rad³]
    T_delta: float = 1.0  # steering-gear time constant [s] (eq. (35): u̇ = u_z − u)
    delta_max: float = 0.6  # rudder angle limit [rad]
    delta_dot_max: float = 0.066  # rudder rate limit [rad/s]
    L: float = 172.0  # ship length [m]

    positive: ClassVar[tuple[str, ...]] = (
        "a3",
        "f",
        "T_delta",
        "delta_max",
        "delta_dot_max",
        "L",
    )
    #: fields that must be ≥ 0 (physical); S = 0 is a stopped engine
    nonnegative: ClassVar[tuple[str, ...]] = ("a2", "W", "S")

    def problems(self) -> list[str]:
        out = super().problems()
        if not out and self.a1 <= 0 and self.a2 == 0:
            out.append(
                f"{type(self).__name__}.a1 must be > 0 when a2 = 0 (no yaw damping), "
                f"got a1 = {self.a1}"
            )
        return out


#: Mariner yaw inertia split (Fossen's mariner.m, prime ×1e-5 removed): I'_z, N'_ṙ
MARINER_IZ, MARINER_NRDOT = 39.2e-5, -43.8e-5


class Mariner(ShipModel):
    """mariner: de Wit–Oppe model of the m.s. Compass Island (Borkowski 2018 eq. (35))."""

    name = "mariner"
    state_names = ("x", "y", "psi", "r", "u", "v", "delta")
    disturbance_names = ("current_x", "current_y", "yaw_disturbance")
    params_type = MarinerParams
    rudder_limit = 0.6  # δmax [rad] (Borkowski 2018 §5); per instance: params.delta_max
    rudder_rate_limit = 0.066  # δ̇max [rad/s] (Borkowski 2018 §5); per instance: params
    #: Mariner class after Chislett & Strøm-Tejsen (1965) (B, C_B as commonly quoted, T from
    #: Fossen's m' = 798e-5 = C_B·B·T/(½L²): an assumption), for a loading change
    hull = Hull(L=160.93, B=23.17, T=7.47, C_B=0.6)

    @classmethod
    def loading_change(
        cls, params: ParameterRecord, factors: dict[str, float], draught_ratio: float
    ) -> dict[str, float]:
        """The loading change of ṙ = −a1·r − a2·r³ + a3·δ, read as the yaw row of the linear
        model without sway coupling, a1 = −N_r/(I_z − N_ṙ), a3 = N_δ/(I_z − N_ṙ): a1 × f_Nr/f_I
        and a3 × 1/f_I, f_I the factor of (I_z − N_ṙ) split as :data:`MARINER_IZ`,
        :data:`MARINER_NRDOT`."""
        if not isinstance(params, MarinerParams):
            raise TypeError(f"mariner needs MarinerParams, got {type(params).__name__}")
        f_inertia = inertia_after(MARINER_IZ, MARINER_NRDOT, factors, "Nrdot") / (
            MARINER_IZ - MARINER_NRDOT
        )
        return {"a1": params.a1 * factors["Nr"] / f_inertia, "a3": params.a3 / f_inertia}

    control_period = 1.0  # Ts [s] (our choice; the paper gives none)
    fine_step = 0.1  # h [s] (our choice)
    #: "algebraic": v = r1·r + r3·r³ (units of r1, r3; data file §2.1);
    #: "printed": eq. (35) as printed, v̇ = −r1·r − r3·r³ (see the module docstring)
    variants = ("algebraic", "printed")

    def __init__(self, params: ParameterRecord | None = None, variant: str | None = None) -> None:
        super().__init__(params, variant)
        self.rudder_limit = float(self.params.delta_max)
        self.rudder_rate_limit = float(self.params.delta_dot_max)

    def rhs(self, x: Any, u: Any, w: Any, p: Any, ops: SimpleNamespace) -> Any:
        psi, r, speed, v_state, delta = x[2], x[3], x[4], x[5], x[6]
        # Borkowski (2018) eq. (35), lines 4, 5 and 7–9
        r_dot = -p.a1 * r - p.a2 * r * r * r + p.a3 * delta + w[2]
        speed_dot = -p.f * speed - p.W * r * r + p.S
        delta_z = ops.clip(u[0], -p.delta_max, p.delta_max)
        delta_dot = ops.clip((delta_z - delta) / p.T_delta, -p.delta_dot_max, p.delta_dot_max)
        if self.variant == "printed":
            v = v_state
            v_dot = -p.r1 * r - p.r3 * r * r * r  # eq. (35) line 6 as printed
        else:
            v = p.r1 * r + p.r3 * r * r * r  # line 6 read as algebraic (see docstring)
            v_dot = (p.r1 + 3.0 * p.r3 * r * r) * r_dot
        cos_psi, sin_psi = ops.cos(psi), ops.sin(psi)
        return ops.stack(
            [
                speed * cos_psi - v * sin_psi + w[0],  # eq. (35) line 1 + current
                speed * sin_psi + v * cos_psi + w[1],  # eq. (35) line 2 + current
                r,
                r_dot,
                speed_dot,
                v_dot,
                delta_dot,
            ]
        )

    def sway(self, r: Any) -> Any:
        """Sway speed v = r1·r + r3·r³ [m/s] of the default variant at yaw rate r [rad/s]."""
        p = self.params
        return p.r1 * r + p.r3 * r**3

    def steady_turn(self, delta: float) -> tuple[float, float, float]:
        """Steady turn at rudder δ [rad]: (r [rad/s], u [m/s], v [m/s]) from ṙ = u̇ = 0.

        r is the real root of a1·r + a2·r³ = a3·δ (unique for a1 > 0), u = (S − W·r²)/f,
        v = r1·r + r3·r³ (default variant).
        """
        p = self.params
        roots = np.roots([p.a2, 0.0, p.a1, -p.a3 * delta]) if p.a2 else [p.a3 * delta / p.a1]
        real = [float(z.real) for z in np.atleast_1d(roots) if abs(z.imag) < 1e-12]
        if len(real) != 1:
            raise ParameterError(
                f"{self.name}: steady turn at δ = {delta} rad is not unique (a1 = {p.a1})"
            )
        r = real[0]
        return r, (p.S - p.W * r * r) / p.f, float(self.sway(r))

    def cruise_state(self, **values: float) -> np.ndarray:
        """Straight ahead at the equilibrium speed u = S/f [m/s] (unless ``u`` is given).

        In the default variant ``v`` is set to r1·r + r3·r³ of the given r unless given.
        """
        values = dict(values)
        values.setdefault("u", self.nominal_speed)
        if self.variant != "printed":
            values.setdefault("v", float(self.sway(values.get("r", 0.0))))
        return self.initial_state(**values)

    @property
    def nominal_speed(self) -> float:
        """Straight-line equilibrium speed S/f [m/s] (7.857 m/s; the paper starts at 7.7)."""
        return self.params.S / self.params.f


#: the mariner ship
SHIP = Ship(
    model=Mariner,
    adapted=hull_quantities("T_delta", "delta_dot_max", "a3"),
    env_ids=(
        EnvId("ShipPathFollow-Mariner-v0", "mariner_track", 2400),
        EnvId("ShipPathFollow-Mariner-v1", "mariner_rudder_aging", 894),
    ),
    published=(
        Published(
            "steady_turn_rate",
            0.0191,
            "Borkowski (2018) §5: r_max at full rudder (0.6 rad; our turn at the rudder limit)",
            0.01,
            "1 %: a closed form of the same model",
        ),
    ),
)

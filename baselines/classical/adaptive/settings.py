"""Settings of the adaptive backstepping controllers and their gains on a ship — Xu,
Oliveira & Guedes Soares (2021) §5.2.

Gains (§5.2): K1 = 0.02, K2 = 15, Γ1 = 100·Iz, Γ2 = 10·Iz, γρ = γσ = 20, γb = 10,
ρ̂(0) = σ̂(0) = 1, b̂(0) = 0, ω = 0.25 rad/s, ζ = 1.  Choices where the paper is silent:

* **Iz in Γ1 = 100·Iz, Γ2 = 10·Iz.**  The paper calls Iz "the inertia moment of the scaled
  ship model" without a value or unit; a Nomoto-model ship (nomoto2) has none, and the
  dimensional value (≈ 10² kg·m² for the 1:100 Esso Osaka) would put the predictor poles at
  10⁴ 1/s.  We read Iz as the unit factor of the scalar predictor (Γ·I in the L1
  literature): Γ1 = 100 1/s, Γ2 = 10 1/s (``gamma1``, ``gamma2``).
* **Projection bounds** (the paper gives none): ρ̂, σ̂ ∈ [0.1, 10] (positive, a factor of
  ten either way), |b̂| ≤ K·δmax (a larger bias cannot be held by the rudder); ε = 0.1
  (:mod:`.projection`).
* **Gain transfer** (``gain_transfer``).  The §5.2 gains were chosen for the 1:100 Esso
  Osaka model (L = 3.25 m, U0 = 0.41 m/s); nothing in the paper says how they carry to
  another ship, and used literally they fail on ships of another size (on nomoto2, whose
  L/U is 6.7 times shorter, the 4-s filter destabilises the loop; on the 172-m Mariner the
  TVVF in metres is a step at ±30 m and the −z1 term alone asks for 23 rad of rudder per
  rad of heading error).  Default ``"similarity"``: the paper's design scaled to the ship
  by its time scale τ = (L/U)/(L/U)_paper and length scale λ = L/L_paper (the prime
  system of the paper's model).  Divided by τ: K1, Γ1, Γ2, γb [1/s], ω and the weight c
  of the −c·z1 term of eq. (35) (c = 1 s⁻¹ implicitly in the paper: with
  V2 = ½z1² + ½T·z2²/c the law gives T·ż2 = −c·z1 − K2·z2 and cancels the cross term);
  multiplied by τ: γρ, γσ [s]; kept: K2 (dimensionless); the TVVF's metre becomes λ
  metres (ye/λ and Δ/λ in the law) unless the scenario measures ye in ship lengths.  On
  the paper's ship τ = 0.996 and λ = 1 (the printed gains within 0.4 %).  ``"literal"``
  uses the printed numbers on every ship.
"""

from __future__ import annotations

import dataclasses

from shipgym.guidance import TVVF_PAPER_SHIP_LENGTH

#: where the low-pass filter C(s) acts (:mod:`shipgym_baselines.classical.l1_backstepping`,
#: "Filter placement")
FILTER_PLACEMENTS = ("command", "adaptive")
#: how the §5.2 gains carry to another ship (module doc, "Gain transfer")
GAIN_TRANSFERS = ("similarity", "literal")
#: unit of ye and Δ in the TVVF law: None = the scenario's (context.guidance), "m", "L"
ERROR_UNITS = (None, "m", "L")
#: the paper's ship: Esso Osaka 1:100 model, L = 325 m / 100, U0 = 0.41 m/s (§5.2)
PAPER_SHIP_LENGTH = TVVF_PAPER_SHIP_LENGTH  # [m], the 1:100 Esso Osaka model
PAPER_SHIP_SPEED = 0.41  # [m/s]


@dataclasses.dataclass(frozen=True)
class L1BacksteppingSettings:
    """Xu, Oliveira & Guedes Soares (2021) §5.2 values plus the choices of the module doc.

    The gains are the paper's, for the paper's ship; ``gain_transfer`` says how they are
    carried to the ship at hand (module doc, "Gain transfer").  Validated on construction.
    """

    K1: float = 0.02  # [1/s]
    K2: float = 15.0  # [-]
    z1_weight: float = 1.0  # c [1/s] of the −c·z1 term of eq. (35) (1 in the paper)
    gamma1: float = 100.0  # Γ1 = 100·Iz [1/s], Iz read as 1 (module doc)
    gamma2: float = 10.0  # Γ2 = 10·Iz [1/s]
    gamma_rho: float = 20.0  # γρ [s]
    gamma_sigma: float = 20.0  # γσ [s]
    gamma_b: float = 10.0  # γb [1/s]
    rho0: float = 1.0
    sigma0: float = 1.0
    b0: float = 0.0  # [rad/s]
    rho_bounds: tuple[float, float] = (0.1, 10.0)
    sigma_bounds: tuple[float, float] = (0.1, 10.0)
    b_bound_rudder: float = 1.0  # |b̂| ≤ b_bound_rudder·|K|·δmax
    projection_epsilon: float = 0.1
    filter_frequency: float = 0.25  # ω [rad/s]
    filter_damping: float = 1.0  # ζ
    #: where C(s) acts (:mod:`shipgym_baselines.classical.l1_backstepping`, "Filter placement"):
    #: "command" (eq. (39) as printed: the whole law) or "adaptive" (only the estimates'
    #: share of it, the standard L1 structure)
    filter_placement: str = "command"
    drift_compensation: bool = True  # subtract the measured drift angle β (eq. (48))
    #: unit of ye and Δ in the TVVF law: None = the scenario's (context.guidance), "m", "L"
    error_unit: str | None = None
    #: "similarity": time- and length-scale the gains from the paper's ship; "literal": as is
    gain_transfer: str = "similarity"
    paper_ship_length: float = PAPER_SHIP_LENGTH  # [m]
    paper_ship_speed: float = PAPER_SHIP_SPEED  # [m/s]

    def __post_init__(self) -> None:
        if not (self.K1 > 0 and self.K2 > 0 and self.z1_weight >= 0):
            raise ValueError(
                f"need K1, K2 > 0 and z1_weight ≥ 0, got {self.K1}, {self.K2}, {self.z1_weight}"
            )
        if self.error_unit not in ERROR_UNITS:
            raise ValueError(f"error_unit must be 'm', 'L' or None, got {self.error_unit!r}")
        if self.gain_transfer not in GAIN_TRANSFERS:
            raise ValueError(
                f"gain_transfer must be 'similarity' or 'literal', got {self.gain_transfer!r}"
            )
        if self.gain_transfer == "similarity" and not (
            self.paper_ship_length > 0 and self.paper_ship_speed > 0
        ):
            raise ValueError("paper_ship_length and paper_ship_speed must be > 0")
        if self.filter_placement not in FILTER_PLACEMENTS:
            raise ValueError(
                f"filter_placement must be one of {FILTER_PLACEMENTS}, "
                f"got {self.filter_placement!r}"
            )


@dataclasses.dataclass(frozen=True)
class Gains:
    """The gains in use on one ship (after the gain transfer), SI."""

    K1: float  # [1/s]
    K2: float  # [-]
    z1_weight: float  # [1/s]
    gamma1: float  # [1/s]
    gamma2: float  # [1/s]
    gamma_rho: float  # [s]
    gamma_sigma: float  # [s]
    gamma_b: float  # [1/s]
    filter_frequency: float  # [rad/s]
    error_unit: float  # [m], unit of ye and Δ in the TVVF law
    time_scale: float  # τ [-], ship time over paper-ship time (1: literal)

    @classmethod
    def transfer(
        cls, s: L1BacksteppingSettings, ship_length: float, ship_speed: float, unit: str
    ) -> Gains:
        """Gains for a ship of length L [m] at speed U [m/s] (module doc, "Gain transfer").

        ``unit`` is the TVVF error unit asked for ("m" or "L").
        """
        if s.gain_transfer == "literal":
            tau, length_scale = 1.0, 1.0
        else:  # "similarity"
            tau = (ship_length / ship_speed) / (s.paper_ship_length / s.paper_ship_speed)
            length_scale = ship_length / s.paper_ship_length
        return cls(
            K1=s.K1 / tau,
            K2=s.K2,
            z1_weight=s.z1_weight / tau,
            gamma1=s.gamma1 / tau,
            gamma2=s.gamma2 / tau,
            gamma_rho=s.gamma_rho * tau,
            gamma_sigma=s.gamma_sigma * tau,
            gamma_b=s.gamma_b / tau,
            filter_frequency=s.filter_frequency / tau,
            error_unit=ship_length if unit == "L" else length_scale,
            time_scale=tau,
        )

"""The ship-model protocol: one right-hand side, evaluated by numpy and by CasADi.

Every ship model writes its dynamics once, in :meth:`ShipModel.rhs`, against a small
math *backend* (``NUMPY`` or ``CASADI``).  The same expression then

* runs in numpy on one ship (state shape ``(n_x,)``) or a batch (``(n_x, N)``),
* builds CasADi SX graphs for NMPC and linearisation, and
* compiles into the CasADi period integrator that the single env uses for speed.

Pattern after pc-gym's models (a dataclass whose call works on numpy and CasADi alike)
and PythonVehicleSimulator's actuator-in-the-plant habit.
"""

from __future__ import annotations

import dataclasses
import math
from abc import ABC, abstractmethod
from collections.abc import Callable, Sequence
from functools import cached_property
from types import SimpleNamespace
from typing import Any, ClassVar

import casadi as ca
import numpy as np

from shipgym.errors import ShipgymError
from shipgym.models.hull import Hull


class ParameterError(ShipgymError, ValueError):
    """A model parameter is non-physical (e.g. a time constant ≤ 0).

    ``problems`` holds one message per bad parameter (the error's text joins them), so that
    a config check can name every one, not only the first.
    """

    def __init__(self, *problems: str) -> None:
        super().__init__("; ".join(problems))
        self.problems: tuple[str, ...] = problems


def _np_stack(rows: Sequence[Any]) -> np.ndarray:
    return np.stack(np.broadcast_arrays(*rows))


#: numpy backend: works on floats, 1-D states and batched ``(n_x, N)`` states.
NUMPY = SimpleNamespace(
    name="numpy",
    sin=np.sin,
    cos=np.cos,
    tanh=np.tanh,
    atan=np.arctan,
    exp=np.exp,
    sign=np.sign,
    sqrt=np.sqrt,
    abs=np.abs,
    atan2=np.arctan2,
    fmin=np.minimum,
    fmax=np.maximum,
    clip=np.clip,
    stack=_np_stack,
)

#: CasADi backend: SX/MX symbols.
CASADI = SimpleNamespace(
    name="casadi",
    sin=ca.sin,
    cos=ca.cos,
    tanh=ca.tanh,
    atan=ca.atan,
    exp=ca.exp,
    sign=ca.sign,
    sqrt=ca.sqrt,
    abs=ca.fabs,
    atan2=ca.atan2,
    fmin=ca.fmin,
    fmax=ca.fmax,
    clip=lambda a, lo, hi: ca.fmin(ca.fmax(a, lo), hi),
    stack=lambda rows: ca.vertcat(*rows),
)


@dataclasses.dataclass(frozen=True)
class ParameterRecord:
    """Base of the typed, validated parameter records (SI units, radians).

    Subclasses list their fields with units in comments and name the fields that must be
    strictly positive in ``positive`` (and ≥ 0 in ``nonnegative``); further rules go in an
    override of :meth:`problems`.  These hold for every record, an identifier's estimate
    included.  ``plant_positive`` / ``plant_nonnegative`` name what a *real* plant needs on
    top (e.g. nomoto2's gain K > 0, which a noisy estimate may violate): :meth:`check_plant`
    enforces them where a ship is built from a config (a scenario's true parameters).
    Records convert to and from a flat vector (field order) so that a CasADi solver can
    take them as parameters.
    """

    positive: ClassVar[tuple[str, ...]] = ()
    nonnegative: ClassVar[tuple[str, ...]] = ()
    plant_positive: ClassVar[tuple[str, ...]] = ()
    plant_nonnegative: ClassVar[tuple[str, ...]] = ()

    def __post_init__(self) -> None:
        problems = self.problems()
        if problems:
            raise ParameterError(*problems)

    def problems(self) -> list[str]:
        """Every rule of a valid record this one breaks, one message each (empty: valid)."""
        cls = type(self).__name__
        out = []
        for name in self.names():
            value = getattr(self, name)
            if not isinstance(value, int | float) or isinstance(value, bool):
                out.append(f"{cls}.{name} must be a number, got {value!r}")
            elif not math.isfinite(value):
                out.append(f"{cls}.{name} must be finite, got {value}")
        if out:
            return out
        out += self._sign_problems(self.positive, self.nonnegative)
        return out

    def plant_problems(self) -> list[str]:
        """:meth:`problems` and the rules of a real plant (``plant_positive``, …)."""
        return self.problems() + self._sign_problems(self.plant_positive, self.plant_nonnegative)

    def check_plant(self) -> None:
        """Raise :class:`ParameterError` naming every parameter a real ship cannot have."""
        problems = self.plant_problems()
        if problems:
            raise ParameterError(*problems)

    def plant(self, **changes: float) -> ParameterRecord:
        """This record with ``changes``, as a real plant: :class:`ParameterError` names
        every rule it breaks, the record's and the plant's together (not only the first)."""
        unknown = set(changes) - set(self.names())
        if unknown:
            return self.replace(**changes)  # raises, naming the unknown names
        # the rules are methods of a record: apply them to an unvalidated instance first
        unchecked = object.__new__(type(self))
        for name in self.names():
            object.__setattr__(unchecked, name, changes.get(name, getattr(self, name)))
        problems = unchecked.plant_problems()
        if problems:
            raise ParameterError(*problems)
        return self.replace(**changes)

    def _sign_problems(self, positive: Sequence[str], nonnegative: Sequence[str]) -> list[str]:
        cls = type(self).__name__
        out = [
            f"{cls}.{name} must be > 0 (physical), got {getattr(self, name)}"
            for name in positive
            if getattr(self, name) <= 0
        ]
        out += [
            f"{cls}.{name} must be ≥ 0 (physical), got {getattr(self, name)}"
            for name in nonnegative
            if getattr(self, name) < 0
        ]
        return out

    @classmethod
    def names(cls) -> tuple[str, ...]:
        names = cls.__dict__.get("_names")  # a class's own (not a base class's), built once
        if names is None:
            names = tuple(f.name for f in dataclasses.fields(cls))
            type.__setattr__(cls, "_names", names)
        return names

    def to_vector(self) -> np.ndarray:
        return np.array([float(getattr(self, n)) for n in self.names()])

    @classmethod
    def from_vector(cls, vector: Sequence[float]) -> ParameterRecord:
        names = cls.names()
        if len(vector) != len(names):
            raise ParameterError(f"{cls.__name__} needs {len(names)} values, got {len(vector)}")
        return cls(**{n: float(v) for n, v in zip(names, vector, strict=True)})

    def replace(self, **changes: float) -> ParameterRecord:
        unknown = set(changes) - set(self.names())
        if unknown:
            raise ParameterError(
                f"{type(self).__name__} has no parameter(s) {sorted(unknown)}; "
                f"valid: {list(self.names())}"
            )
        return dataclasses.replace(self, **changes)

    def as_dict(self) -> dict[str, float]:
        return {n: float(getattr(self, n)) for n in self.names()}


def parameter_view(names: Sequence[str], vector: Any) -> SimpleNamespace:
    """Attribute access ``p.K`` into a parameter vector (numpy rows or CasADi SX entries)."""
    return SimpleNamespace(**{n: vector[i] for i, n in enumerate(names)})


def current_in_body(w: Any, cos_psi: Any, sin_psi: Any) -> tuple[Any, Any]:
    """Body-frame components (u_c, v_c) [m/s] of the earth-frame current (w[0], w[1]) [m/s,
    flowing *to*] at heading ψ (given as cos ψ, sin ψ); numpy or CasADi alike."""
    return w[0] * cos_psi + w[1] * sin_psi, -w[0] * sin_psi + w[1] * cos_psi


def rk4_step(
    f: Callable[[Any, Any, Any, Any], Any], x: Any, u: Any, w: Any, p: Any, h: float
) -> Any:
    """One classical Runge–Kutta-4 step of ``ẋ = f(x, u, w, p)`` with u, w, p held; h in s.

    Shared by every model and by both backends (numpy arrays or CasADi SX).
    """
    k1 = f(x, u, w, p)
    k2 = f(x + (0.5 * h) * k1, u, w, p)
    k3 = f(x + (0.5 * h) * k2, u, w, p)
    k4 = f(x + h * k3, u, w, p)
    return x + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)


class ShipModel(ABC):
    """A ship model: states, input, disturbance inputs, parameters and one rhs.

    Subclasses set the class attributes and implement :meth:`rhs`.  States are SI / rad.
    ``disturbance_names`` are exogenous inputs the environment drives (currents, wave
    loads); they are zero for a calm sea.
    """

    name: ClassVar[str]
    state_names: ClassVar[tuple[str, ...]]
    input_names: ClassVar[tuple[str, ...]] = ("rudder_command",)
    disturbance_names: ClassVar[tuple[str, ...]]
    params_type: ClassVar[type[ParameterRecord]]
    #: rudder angle limit [rad] and rate limit [rad/s] (inf when the servo has none)
    rudder_limit: float
    rudder_rate_limit: float = math.inf
    #: default control period Ts and fine integration step h [s]
    control_period: ClassVar[float]
    fine_step: ClassVar[float]
    #: unit readings the model accepts for config/paper numbers (first = default)
    unit_readings: ClassVar[tuple[str, ...]] = ("si",)
    #: structural variants of the equations (first = default), e.g. a source code's
    #: literal form and its corrected form; ``()`` when the model has one form
    variants: ClassVar[tuple[str, ...]] = ()
    #: main particulars at the reference draught, for a loading change
    #: (:mod:`shipgym.models.loading`); None: the model has no loading-condition model
    hull: ClassVar[Hull | None] = None
    #: parameter -> the draught factor it is multiplied by, where a loading change is a
    #: product (:meth:`loading_change`'s default)
    scaled_by: ClassVar[dict[str, str]] = {}
    #: the parameters that hold the length [m] and the nominal speed [m/s], read by
    #: :attr:`length` and :attr:`nominal_speed` (a model that computes a figure overrides it)
    length_parameter: ClassVar[str] = "L"
    speed_parameter: ClassVar[str] = "u0"

    @classmethod
    def loading_change(
        cls, params: ParameterRecord, factors: dict[str, float], draught_ratio: float
    ) -> dict[str, float]:
        """The parameters of ``params`` (config units) that change when the draught becomes
        ``draught_ratio``·T, given the hull's draught factors
        (:func:`shipgym.models.hull.draught_factors`): by default each of :attr:`scaled_by`
        × its factor."""
        if cls.hull is None:
            raise ValueError(f"no loading-condition model for {cls.name!r}")
        return {name: getattr(params, name) * factors[key] for name, key in cls.scaled_by.items()}

    def __init__(self, params: ParameterRecord | None = None, variant: str | None = None) -> None:
        self.params = params if params is not None else self.params_type()
        if not isinstance(self.params, self.params_type):
            raise TypeError(f"{self.name} needs {self.params_type.__name__}, got {params!r}")
        if variant is not None and variant not in self.variants:
            valid = list(self.variants) if self.variants else "none (the model has one form)"
            raise ParameterError(f"{self.name}: unknown variant {variant!r}; valid: {valid}")
        self.variant = variant if variant is not None else (self.variants or (None,))[0]

    def with_params(self, params: ParameterRecord) -> ShipModel:
        """The same model (class and variant) with other parameters."""
        return type(self)(params, self.variant)

    @classmethod
    def config_to_si(cls, values: dict[str, float], unit_reading: str | None) -> dict[str, float]:
        """Convert parameter values as written in configs (paper units) to SI."""
        reading = unit_reading or cls.unit_readings[0]
        if reading not in cls.unit_readings:
            raise ParameterError(
                f"{cls.name}: unknown unit_reading {reading!r}; valid: {list(cls.unit_readings)}"
            )
        unknown = set(values) - set(cls.params_type.names())
        if unknown:
            raise ParameterError(
                f"{cls.name} has no parameter(s) {sorted(unknown)}; "
                f"valid: {list(cls.params_type.names())}"
            )
        return dict(values)

    @classmethod
    def from_config(
        cls, values: dict[str, float], unit_reading: str | None = None, variant: str | None = None
    ) -> ShipModel:
        """The model with its default parameters overridden by ``values`` (config units):
        a real plant, so :meth:`ParameterRecord.plant` checks them."""
        return cls(cls.params_type().plant(**cls.config_to_si(values, unit_reading)), variant)

    # -- the one definition -------------------------------------------------------------
    @abstractmethod
    def rhs(self, x: Any, u: Any, w: Any, p: Any, ops: SimpleNamespace) -> Any:
        """ẋ = f(x, u, w, p).  x, u, w index like sequences, p has attribute access."""

    # -- declared figures ---------------------------------------------------------------
    @property
    def length(self) -> float:
        """Ship length L [m]: the parameter :attr:`length_parameter`."""
        return float(getattr(self.params, self.length_parameter))

    @property
    def nominal_speed(self) -> float:
        """Nominal (service) speed [m/s]: the parameter :attr:`speed_parameter`."""
        return float(getattr(self.params, self.speed_parameter))

    @property
    def n_states(self) -> int:
        return len(self.state_names)

    @property
    def n_disturbances(self) -> int:
        return len(self.disturbance_names)

    @property
    def n_params(self) -> int:
        return len(self.params_type.names())

    def state_index(self, name: str) -> int:
        return self.state_names.index(name)

    def initial_state(self, **values: float) -> np.ndarray:
        """State vector with the named entries set (others zero); names as ``state_names``."""
        x = np.zeros(self.n_states)
        for key, value in values.items():
            if key not in self.state_names:
                raise KeyError(f"{self.name} has no state {key!r}; states: {self.state_names}")
            x[self.state_names.index(key)] = value
        return x

    def cruise_state(self, **values: float) -> np.ndarray:
        """Straight-ahead state at the nominal speed with the named entries set.

        Start of every manoeuvre and scenario.  Kinematic models (speed a parameter) need
        nothing more than :meth:`initial_state`; models with a surge state override this to
        set u = U0 (and propeller speed, controller states) unless given in ``values``.
        """
        return self.initial_state(**values)

    def closed_form_nomoto(self) -> tuple[float, float, float, float] | None:
        """The 2nd-order Nomoto model (K [1/s], T1, T2, T3 [s]) in closed form, or None.

        None (the default): the model has none, and
        :func:`shipgym.identification.nominal.second_order_nomoto` identifies it from the ship's
        20/20 zig-zag instead.
        """
        return None

    def __getstate__(self) -> dict[str, Any]:
        # CasADi functions are rebuilt on demand after unpickling
        return {k: v for k, v in self.__dict__.items() if k != "casadi_rhs"}

    # -- numpy evaluation ---------------------------------------------------------------
    def f_numpy(self, x: np.ndarray, u: Any, w: Any, p_vector: np.ndarray) -> np.ndarray:
        """rhs with numpy; x (n_x,) or (n_x, N); p_vector (n_p,) or (n_p, N)."""
        return self.rhs(x, u, w, parameter_view(self.params_type.names(), p_vector), NUMPY)

    def step_numpy(
        self, x: np.ndarray, u: Any, w: Any, p_vector: np.ndarray, h: float
    ) -> np.ndarray:
        """One RK4 step of length h [s] in numpy (single or batched)."""
        return rk4_step(self.f_numpy, x, u, w, p_vector, h)

    # -- CasADi evaluation --------------------------------------------------------------
    @cached_property
    def casadi_rhs(self) -> ca.Function:
        """``f(x, u, w, p) -> ẋ`` as a CasADi SX Function (p: parameter vector)."""
        x = ca.SX.sym("x", self.n_states)
        u = ca.SX.sym("u", len(self.input_names))
        w = ca.SX.sym("w", self.n_disturbances)
        p = ca.SX.sym("p", self.n_params)
        xdot = self.rhs(x, u, w, parameter_view(self.params_type.names(), p), CASADI)
        return ca.Function(f"{self.name}_rhs", [x, u, w, p], [xdot], ["x", "u", "w", "p"], ["xdot"])

    def casadi_step(self, h: float) -> ca.Function:
        """One RK4 step of length h [s] as a CasADi Function ``(x, u, w, p) -> x⁺``."""
        f = self.casadi_rhs
        x = ca.SX.sym("x", self.n_states)
        u = ca.SX.sym("u", len(self.input_names))
        w = ca.SX.sym("w", self.n_disturbances)
        p = ca.SX.sym("p", self.n_params)
        x_next = rk4_step(lambda *a: f(*a), x, u, w, p, h)
        return ca.Function(f"{self.name}_rk4", [x, u, w, p], [x_next], ["x", "u", "w", "p"], ["xf"])

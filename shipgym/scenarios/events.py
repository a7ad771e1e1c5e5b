"""Scheduled changes of the true plant parameters (step or ramp)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from shipgym.models.base import ParameterError, ParameterRecord

#: [s] tolerance on event times against accumulated float time
EVENT_TIME_EPS = 1e-9
_EPS = EVENT_TIME_EPS


@dataclasses.dataclass(frozen=True)
class ParameterEvent:
    """At ``time`` [s] set ``values`` (SI); a ramp moves linearly over ``duration`` [s]."""

    time: float
    values: dict[str, float]
    kind: str = "step"
    duration: float = 0.0

    def __post_init__(self) -> None:
        if self.kind not in ("step", "ramp"):
            raise ParameterError(f"event kind must be 'step' or 'ramp', got {self.kind!r}")
        if not (math.isfinite(self.time) and self.time >= 0):
            raise ParameterError(f"event time must be finite and ≥ 0 s, got {self.time}")
        if self.kind == "ramp" and not (math.isfinite(self.duration) and self.duration > 0):
            raise ParameterError(f"a ramp event needs a finite duration > 0 s, got {self.duration}")

    def end_time(self) -> float:
        return self.time + (self.duration if self.kind == "ramp" else 0.0)


class ParameterSchedule:
    """True parameters over time: the nominal record changed by a list of events.

    Every intermediate record is validated on construction (a non-physical jump fails when
    the scenario loads, not mid-episode), and no event may start while a ramp is running.
    """

    def __init__(self, nominal: ParameterRecord, events: list[ParameterEvent]) -> None:
        self.nominal = nominal
        self.events = sorted(events, key=lambda e: e.time)
        self.names = nominal.names()
        self._index = {n: i for i, n in enumerate(self.names)}
        # value vectors before and after each event
        self._before: list[np.ndarray] = []
        self._after: list[np.ndarray] = []
        current = nominal
        for i, event in enumerate(self.events):
            previous = self.events[i - 1] if i else None
            if previous is not None and event.time < previous.end_time() - _EPS:
                raise ParameterError(
                    f"the event at {event.time} s starts during the ramp from "
                    f"{previous.time} s to {previous.end_time()} s"
                )
            self._before.append(current.to_vector())
            current = current.replace(**event.values)  # validates
            self._after.append(current.to_vector())
        self.final = current
        self._nominal_vector = nominal.to_vector()

    @property
    def first_change_time(self) -> float | None:
        return self.events[0].time if self.events else None

    def vector_at(self, t: float) -> np.ndarray:
        """Parameter vector in force at time t [s]."""
        vector = self._nominal_vector
        for event, before, after in zip(self.events, self._before, self._after, strict=True):
            if t < event.time - _EPS:
                break
            if event.kind == "ramp" and t < event.end_time():
                frac = (t - event.time) / event.duration
                return before + (after - before) * frac
            vector = after
        return vector

    def record_at(self, t: float) -> ParameterRecord:
        return type(self.nominal).from_vector(self.vector_at(t))

    def is_constant_on(self, t0: float, t1: float) -> bool:
        """True when no event starts or is ramping within [t0, t1] [s]."""
        return all(e.end_time() < t0 - _EPS or e.time > t1 + _EPS for e in self.events)

    def changing_on(self, t0: np.ndarray, t1: np.ndarray) -> np.ndarray:
        """:meth:`is_constant_on` negated, elementwise over arrays of periods [t0, t1] [s]."""
        changing = np.zeros(np.shape(t0), dtype=bool)
        for e in self.events:
            changing |= (e.end_time() >= t0 - _EPS) & (e.time <= t1 + _EPS)
        return changing

    def fill_matrix(self, t0: float, h: float, out: np.ndarray) -> None:
        """Fill ``out`` (n, n_p): row i = parameters of the substep starting at t0 + i·h."""
        for i in range(out.shape[0]):
            out[i] = self.vector_at(t0 + i * h)

    def changed_names(self) -> set[str]:
        names: set[str] = set()
        for before, after in zip(self._before, self._after, strict=True):
            names |= {n for n, i in self._index.items() if not math.isclose(before[i], after[i])}
        return names

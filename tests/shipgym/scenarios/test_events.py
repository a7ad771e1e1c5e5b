"""Tests for the parameter schedule (shipgym.scenarios.events): steps, ramps, substep rows."""

from __future__ import annotations

import numpy as np
import pytest

from shipgym.models.base import ParameterError
from shipgym.models.nomoto2 import Nomoto2Params
from shipgym.scenarios.events import ParameterEvent, ParameterSchedule

NOMINAL = Nomoto2Params()  # Tc = 0.1 s, K = 0.506 1/s
I_TC = Nomoto2Params.names().index("Tc")
I_K = Nomoto2Params.names().index("K")


def step_and_ramp() -> ParameterSchedule:
    """Tc: 0.1 → 0.5 s at 10 s (step); K: 0.506 → 1.006 1/s ramped over [20, 24] s."""
    return ParameterSchedule(
        NOMINAL,
        [ParameterEvent(20.0, {"K": 1.006}, "ramp", 4.0), ParameterEvent(10.0, {"Tc": 0.5})],
    )


@pytest.mark.parametrize(
    ("t", "tc", "k"),
    [
        (0.0, 0.1, 0.506),
        (10.0 - 1e-6, 0.1, 0.506),  # just before the step
        (10.0 - 1e-12, 0.5, 0.506),  # within the float tolerance of the event time: after
        (10.0, 0.5, 0.506),
        (20.0, 0.5, 0.506),  # the ramp starts from the value before it
        (21.0, 0.5, 0.631),  # a quarter of the way
        (22.0, 0.5, 0.756),  # half way
        (24.0, 0.5, 1.006),
        (1e4, 0.5, 1.006),
    ],
)
def test_values_at_times(t: float, tc: float, k: float) -> None:
    vector = step_and_ramp().vector_at(t)
    assert vector[I_TC] == pytest.approx(tc, rel=1e-12)
    assert vector[I_K] == pytest.approx(k, rel=1e-12)
    others = np.delete(vector, [I_TC, I_K])
    np.testing.assert_array_equal(others, np.delete(NOMINAL.to_vector(), [I_TC, I_K]))


def test_events_are_applied_in_time_order_and_compose() -> None:
    s = step_and_ramp()
    assert [e.time for e in s.events] == [10.0, 20.0]
    assert s.first_change_time == 10.0
    assert s.final == NOMINAL.replace(Tc=0.5, K=1.006)
    assert s.record_at(30.0) == s.final
    assert isinstance(s.record_at(5.0), Nomoto2Params) and s.record_at(5.0) == NOMINAL
    assert s.changed_names() == {"Tc", "K"}


def test_setting_a_parameter_to_its_value_changes_nothing() -> None:
    s = ParameterSchedule(NOMINAL, [ParameterEvent(5.0, {"Tc": NOMINAL.Tc, "K": 2.0})])
    assert s.changed_names() == {"K"}


def test_no_events_is_the_nominal_record_forever() -> None:
    s = ParameterSchedule(NOMINAL, [])
    assert s.first_change_time is None and s.final == NOMINAL
    for t in (0.0, 1e6):
        np.testing.assert_array_equal(s.vector_at(t), NOMINAL.to_vector())
    assert s.is_constant_on(0.0, 1e6)


def test_fill_matrix_rows_are_the_values_at_the_substep_starts() -> None:
    s = step_and_ramp()
    h, n = 0.25, 40
    for t0 in (9.0, 19.5, 23.0):  # across the step, into the ramp, out of the ramp
        out = np.full((n, NOMINAL.to_vector().size), np.nan)
        s.fill_matrix(t0, h, out)
        for i in range(n):
            np.testing.assert_array_equal(out[i], s.vector_at(t0 + i * h))
    out = np.zeros((8, NOMINAL.to_vector().size))
    s.fill_matrix(9.0, 0.25, out)  # rows at 9.0, 9.25, …, 10.75: the step at row 4
    np.testing.assert_array_equal(out[:4, I_TC], 0.1)
    np.testing.assert_array_equal(out[4:, I_TC], 0.5)


@pytest.mark.parametrize(
    ("t0", "t1", "constant"),
    [
        (0.0, 9.5, True),
        (9.5, 10.0, False),  # the step at the period's end
        (10.0, 10.5, False),  # … and at its start
        (10.5, 19.5, True),
        (19.5, 20.5, False),
        (21.0, 22.0, False),  # inside the ramp
        (23.5, 24.5, False),  # the ramp ends inside
        (24.5, 30.0, True),
    ],
)
def test_is_constant_on(t0: float, t1: float, constant: bool) -> None:
    s = step_and_ramp()
    assert s.is_constant_on(t0, t1) is constant
    assert bool(s.changing_on(np.array([t0]), np.array([t1]))[0]) is not constant


@pytest.mark.parametrize(
    ("events", "match"),
    [
        ([ParameterEvent(5.0, {"Tc": 0.0})], "Tc"),  # a non-physical jump (Tc > 0)
        ([ParameterEvent(5.0, {"T1": 1.0}), ParameterEvent(8.0, {"T1": -2.0})], "T1"),
        ([ParameterEvent(5.0, {"Tk": 1.0})], "Tk"),  # no such parameter
        (
            [ParameterEvent(5.0, {"K": 1.0}, "ramp", 4.0), ParameterEvent(7.0, {"Tc": 0.2})],
            "during the ramp",
        ),
    ],
)
def test_bad_schedules_fail_on_construction(events: list[ParameterEvent], match: str) -> None:
    with pytest.raises(ParameterError, match=match):
        ParameterSchedule(NOMINAL, events)


def test_an_event_may_start_where_a_ramp_ends() -> None:
    s = ParameterSchedule(
        NOMINAL, [ParameterEvent(5.0, {"K": 1.0}, "ramp", 4.0), ParameterEvent(9.0, {"Tc": 0.2})]
    )
    assert s.final == NOMINAL.replace(K=1.0, Tc=0.2)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"kind": "rmap"}, "'step' or 'ramp'"),
        ({"kind": "ramp"}, "duration > 0"),
        ({"kind": "ramp", "duration": -1.0}, "duration > 0"),
        ({"time": -1.0}, "≥ 0"),
        ({"time": float("nan")}, "finite"),
    ],
)
def test_bad_events_are_rejected(kwargs: dict, match: str) -> None:
    args = {"time": 5.0, "values": {"Tc": 0.5}, **kwargs}
    with pytest.raises(ParameterError, match=match):
        ParameterEvent(**args)

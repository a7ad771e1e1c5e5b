"""The float and array operation sets of the step core give the same bits."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgym.angles import wrap_angle
from shipgym.numerics import ARRAY, SCALAR

RNG = np.random.default_rng(0)
X = RNG.normal(0.0, 3.0, 5000)
Y = RNG.normal(0.0, 3.0, 5000)
U = np.tanh(X)  # in (−1, 1) for asin


@pytest.mark.parametrize(
    ("name", "args"),
    [
        ("sqrt", (np.abs(X),)),
        ("abs", (X,)),
        ("sin", (X,)),
        ("cos", (X,)),
        ("arcsin", (U,)),
        ("arctan", (X,)),
        ("arctan2", (X, Y)),
        ("exp2", (U,)),
        ("minimum", (X, Y)),
        ("maximum", (X, Y)),
    ],
)
def test_array_ops_equal_scalar_ops_bit_for_bit(name: str, args: tuple) -> None:
    got = getattr(ARRAY, name)(*args)
    want = np.array([getattr(SCALAR, name)(*(float(a[i]) for a in args)) for i in range(X.size)])
    np.testing.assert_array_equal(got, want)


def test_where_any_and_index_helpers_agree() -> None:
    cond = X > 0
    np.testing.assert_array_equal(
        ARRAY.where(cond, X, Y),
        [SCALAR.where(bool(c), x, y) for c, x, y in zip(cond, X, Y, strict=True)],
    )
    assert ARRAY.any(cond) == SCALAR.any(bool(cond.any()))
    table = np.sort(RNG.uniform(0, 10, 50))
    values = RNG.uniform(-1, 11, 200)
    got = ARRAY.clip_index(ARRAY.searchsorted_right(table, values) - 1, 0, 49)
    want = [
        SCALAR.clip_index(SCALAR.searchsorted_right(table.tolist(), v) - 1, 0, 49)
        for v in values.tolist()
    ]
    np.testing.assert_array_equal(got, want)


def test_state_column_helpers_agree() -> None:
    rows = RNG.normal(0.0, 1.0, (40, 5))
    rows[3, 2] = np.nan
    cond = X[:40] > 0
    for j in range(5):
        column = ARRAY.column(rows, j)
        assert not np.shares_memory(column, rows)
        np.testing.assert_array_equal(column, [SCALAR.column(row, j) for row in rows])
    got = ARRAY.columns(rows, (4, 0))
    np.testing.assert_array_equal(
        got, [[SCALAR.columns(r, (4, 0))[i] for r in rows] for i in (0, 1)]
    )
    np.testing.assert_array_equal(
        ARRAY.where_rows(cond, rows, -rows),
        [SCALAR.where_rows(bool(c), r, -r) for c, r in zip(cond, rows, strict=True)],
    )
    assert ARRAY.all_finite(rows).tolist() == [SCALAR.all_finite(r) for r in rows]
    assert ARRAY.all(cond) == SCALAR.all(bool(cond.all()))


def test_wrap_angle_is_the_identity_on_its_range_and_agrees_for_floats_and_arrays() -> None:
    inside = RNG.uniform(-math.pi, math.pi, 1000)
    np.testing.assert_array_equal(wrap_angle(inside), inside)
    wide = np.concatenate([X * 10, [-1e-20, math.pi, -math.pi, 3 * math.pi, -3 * math.pi]])
    w = wrap_angle(wide)
    assert np.all((w >= -math.pi) & (w < math.pi))
    np.testing.assert_array_equal(w, [wrap_angle(float(a)) for a in wide])
    # wrapping changes an angle by whole turns only
    np.testing.assert_allclose(np.cos(w), np.cos(wide), atol=1e-12)
    assert wrap_angle(math.pi) == -math.pi and wrap_angle(-1e-20) == -1e-20

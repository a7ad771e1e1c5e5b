"""The float unwrap equals numpy.unwrap bit for bit (shipgym/angles.py)."""

from __future__ import annotations

import itertools
import math

import numpy as np

from shipgym.angles import unwrap_array, unwrap_floats


def test_unwrap_floats_has_numpys_bits() -> None:
    """Random walks, uniform noise and exact multiples of π (the ±π boundary), 1-24 long."""
    rng = np.random.default_rng(0)
    for n in range(1, 25):
        for k in range(300):
            if k % 3 == 0:
                a = np.cumsum(rng.normal(0.0, 2.0, n))
            elif k % 3 == 1:
                a = rng.uniform(-10.0, 10.0, n)
            else:
                a = math.pi * rng.integers(-3, 4, n).astype(float)
            want = [x.hex() for x in np.unwrap(a).tolist()]
            assert [x.hex() for x in unwrap_floats(a.tolist())] == want, a


def test_unwrap_floats_removes_the_jumps_of_a_turning_heading() -> None:
    heading = [3.0, 3.1, -3.1, -3.0, 3.0]
    out = unwrap_floats(heading)
    assert all(abs(b - a) < math.pi for a, b in itertools.pairwise(out))
    assert out[2] == -3.1 + 2 * math.pi and out[0] == 3.0
    assert unwrap_floats([]) == []


def test_unwrap_array_has_numpys_bits() -> None:
    """Slow walks (the fast path, signed zeros included), jumps and the ±π boundary."""
    rng = np.random.default_rng(1)
    for n in range(0, 60):
        for k in range(60):
            if k % 4 == 0:
                a = np.cumsum(rng.normal(0.0, 0.3, n))
            elif k % 4 == 1:
                a = rng.uniform(-10.0, 10.0, n)
            elif k % 4 == 2:
                a = math.pi * rng.integers(-3, 4, n).astype(float)
            else:
                a = np.where(rng.random(n) < 0.3, -0.0, rng.normal(0.0, 1e-3, n))
            want = [x.hex() for x in np.unwrap(a).tolist()]
            assert [x.hex() for x in unwrap_array(a).tolist()] == want, a
            assert np.signbit(unwrap_array(a)).tolist() == np.signbit(np.unwrap(a)).tolist()

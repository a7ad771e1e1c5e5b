"""The float unwrap equals numpy.unwrap bit for bit (shipgym/angles.py)."""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterator

import numpy as np

from shipgym.angles import unwrap_array, unwrap_floats


def _headings(
    seed: int, lengths: range, per_length: int, step: float, kinds: int
) -> Iterator[np.ndarray]:
    """Arrays to unwrap, ``per_length`` of each length, the kinds in turn: random walks of
    N(0, ``step``) steps, uniform noise on ±10, exact multiples of π (the ±π boundary) and,
    with ``kinds`` = 4, near-zero values with signed zeros."""
    rng = np.random.default_rng(seed)
    for n in lengths:
        for k in range(per_length):
            if k % kinds == 0:
                yield np.cumsum(rng.normal(0.0, step, n))
            elif k % kinds == 1:
                yield rng.uniform(-10.0, 10.0, n)
            elif k % kinds == 2:
                yield math.pi * rng.integers(-3, 4, n).astype(float)
            else:
                yield np.where(rng.random(n) < 0.3, -0.0, rng.normal(0.0, 1e-3, n))


def test_unwrap_floats_has_numpys_bits() -> None:
    """Random walks, uniform noise and exact multiples of π (the ±π boundary), 1-24 long."""
    for a in _headings(0, range(1, 25), 300, 2.0, kinds=3):
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
    for a in _headings(1, range(0, 60), 60, 0.3, kinds=4):
        want = [x.hex() for x in np.unwrap(a).tolist()]
        assert [x.hex() for x in unwrap_array(a).tolist()] == want, a
        assert np.signbit(unwrap_array(a)).tolist() == np.signbit(np.unwrap(a)).tolist()

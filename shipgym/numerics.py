"""Operation sets for code written once for one ship (floats) and for N ships (arrays).

The step core (:mod:`shipgym.tracking`, :mod:`shipgym.guidance`, :mod:`shipgym.autopilot`,
:mod:`shipgym.envs.core`) takes an ``xp`` argument: :data:`SCALAR` for the single env, which
runs on Python floats (fast: no numpy-scalar overhead), or :data:`ARRAY` for the batched env.
Arithmetic (``+ − * /``), comparisons, ``sqrt`` and ``abs`` are correctly rounded IEEE
operations in both, so results agree bit for bit; the transcendental functions of
:data:`SCALAR` are libm's (``math``), those of :data:`ARRAY` numpy's, which may use SIMD
implementations that differ from libm in the last bit: :data:`ARRAY` therefore maps libm's
``asin``, ``atan``, ``atan2`` and ``pow(2, ·)`` over the elements (≈ 60 ns each) and keeps
numpy's ``sin`` and ``cos``, which equal libm's here (checked by
tests/shipgym/test_numerics.py).  So the single env and the batched env agree bit for bit.

Both also read state vectors alike: :data:`SCALAR`'s ``column(x, j)`` is entry j of one
ship's vector as a float, :data:`ARRAY`'s column j of N ships' rows as a fresh array
(``columns``: several at once); ``where_rows`` selects whole rows, ``all_finite`` checks
each ship's vector.
"""

from __future__ import annotations

import bisect
import math
import operator
from typing import Any

import numpy as np

__all__ = ["ARRAY", "SCALAR", "ArrayOps", "ScalarOps"]


def _exp2(a: float) -> float:
    """2^a by libm's pow (Python's ``**`` on floats)."""
    return 2.0**a


class ScalarOps:
    """Python floats and bools (one ship)."""

    batched = False
    sqrt = staticmethod(math.sqrt)
    abs = staticmethod(abs)
    sin = staticmethod(math.sin)
    cos = staticmethod(math.cos)
    arcsin = staticmethod(math.asin)
    arctan = staticmethod(math.atan)
    arctan2 = staticmethod(math.atan2)
    exp2 = staticmethod(_exp2)
    minimum = staticmethod(min)
    maximum = staticmethod(max)
    logical_not = staticmethod(operator.not_)
    any = staticmethod(bool)
    all = staticmethod(bool)

    @staticmethod
    def where(cond: Any, a: Any, b: Any) -> Any:
        return a if cond else b

    @staticmethod
    def column(vector: Any, j: int) -> float:
        """Entry j of one ship's vector (array or list) as a float."""
        return float(vector[j])

    @staticmethod
    def columns(vector: np.ndarray, js: tuple[int, ...]) -> tuple[float, ...]:
        """Entries ``js`` of one ship's vector as floats."""
        return operator.itemgetter(*js)(vector.tolist())

    @staticmethod
    def where_rows(cond: Any, a: Any, b: Any) -> Any:
        return a if cond else b

    @staticmethod
    def all_finite(vector: Any) -> bool:
        """Whether every entry of one ship's vector is finite."""
        return all(map(math.isfinite, vector.tolist()))

    @staticmethod
    def searchsorted_right(table: Any, value: float) -> int:
        """Index i with table[i-1] ≤ value < table[i] (``numpy.searchsorted(side="right")``)."""
        return bisect.bisect_right(table, value)

    @staticmethod
    def clip_index(i: int, lo: int, hi: int) -> int:
        return lo if i < lo else hi if i > hi else i


def _elementwise(f: Any) -> Any:
    """numpy-array version of the libm function ``f`` (same bits as ``f`` on each element)."""

    def apply(*args: Any) -> np.ndarray:
        arrays = np.broadcast_arrays(*(np.asarray(a, dtype=np.float64) for a in args))
        shape = arrays[0].shape
        flat = [a.ravel().tolist() for a in arrays]
        return np.fromiter(map(f, *flat), np.float64, arrays[0].size).reshape(shape)

    apply.__doc__ = f"libm's {f.__name__} over the elements of numpy arrays."
    return staticmethod(apply)


class ArrayOps:
    """numpy arrays over N ships."""

    batched = True
    sqrt = staticmethod(np.sqrt)
    abs = staticmethod(np.abs)
    sin = staticmethod(np.sin)
    cos = staticmethod(np.cos)
    arcsin = _elementwise(math.asin)
    arctan = _elementwise(math.atan)
    arctan2 = _elementwise(math.atan2)
    exp2 = _elementwise(_exp2)
    minimum = staticmethod(np.minimum)
    logical_not = staticmethod(np.logical_not)
    maximum = staticmethod(np.maximum)
    where = staticmethod(np.where)

    @staticmethod
    def any(cond: Any) -> Any:
        return np.asarray(cond).any()  # the array method: no dispatch of np.any

    @staticmethod
    def all(cond: Any) -> bool:
        return bool(np.asarray(cond).all())

    @staticmethod
    def column(rows: Any, j: int) -> np.ndarray:
        """Column j of N ships' rows (N, n) as a fresh array (never a view)."""
        return rows[:, j].copy()

    @staticmethod
    def columns(rows: np.ndarray, js: tuple[int, ...]) -> list[np.ndarray]:
        """Columns ``js`` of N ships' rows (N, n), each a fresh array."""
        return [rows[:, j].copy() for j in js]

    @staticmethod
    def where_rows(cond: Any, a: Any, b: Any) -> np.ndarray:
        """Row i of ``a`` where ``cond[i]``, else of ``b`` ((N, n) arrays, (N,) mask)."""
        return np.where(cond[:, None], a, b)

    @staticmethod
    def all_finite(rows: Any) -> np.ndarray:
        """Per ship: whether every entry of its row of (N, n) is finite."""
        return np.isfinite(rows).all(axis=1)

    @staticmethod
    def searchsorted_right(table: Any, value: Any) -> Any:
        return np.searchsorted(table, value, side="right")

    @staticmethod
    def clip_index(i: Any, lo: int, hi: int) -> Any:
        return np.minimum(np.maximum(i, lo), hi)  # np.clip's values, without its overhead


SCALAR = ScalarOps()
ARRAY = ArrayOps()

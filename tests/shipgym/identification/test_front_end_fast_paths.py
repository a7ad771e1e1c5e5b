"""The front end's fast paths give the numbers of the general ones, bit for bit."""

from __future__ import annotations

import numpy as np

from shipgym.identification.front_end import HampelFilter, _median_mad


def _stream(filter_: HampelFilter, x: np.ndarray, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    out, i = [], 0
    while i < x.size:
        k = int(rng.integers(1, 80))
        out.append(filter_.push(x[i : i + k]))
        i += k
    return np.concatenate(out)


def test_hampel_full_windows_equal_numpys_median_bit_for_bit() -> None:
    """Random walk with spikes, a NaN and a run of inf, pushed in chunks of 1-79 samples:
    the partition path equals ``np.median`` over ``sliding_window_view`` everywhere."""
    rng = np.random.default_rng(0)
    x = np.cumsum(rng.standard_normal(20_000)) * 0.01
    x[rng.integers(0, x.size, 300)] += 1.0
    x[5_000], x[7_000:7_010] = np.nan, np.inf
    x[9_000:9_020] = 0.25  # ties: MAD 0

    class Reference(HampelFilter):
        def _full_median_mad(self, buf, first, count):  # the general path
            full = np.lib.stride_tricks.sliding_window_view(buf, self.window)
            return _median_mad(full[first : first + count])

    for window in (3, 7, 11):
        fast, slow = HampelFilter(window), Reference(window)
        a, b = _stream(fast, x, 1), _stream(slow, x, 1)
        assert a.tobytes() == b.tobytes()
        assert fast.replaced == slow.replaced > 0


def test_row_window_keeps_the_rows_of_a_concatenated_and_trimmed_window() -> None:
    """Appends of 1-120 rows and drops, across compactions and a growth, against vstack."""
    from shipgym.identification.online import _RowWindow

    rng = np.random.default_rng(2)
    window, reference = _RowWindow(3, 64), np.zeros((0, 3))
    for _ in range(400):
        rows = rng.standard_normal((int(rng.integers(1, 121)), 3))
        window.append(rows)
        reference = np.vstack([reference, rows])
        k = int(rng.integers(0, len(window) + 1))
        window.drop(k)
        reference = reference[k:]
        assert window.view().tobytes() == reference.tobytes() and len(window) == len(reference)

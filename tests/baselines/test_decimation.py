"""M4 thinning of a kept trajectory (issue 20): what a figure draws is what it would draw of
the full signal."""

from __future__ import annotations

import numpy as np

from shipgym_baselines.decimation import DRAWN_KEYS, m4_indices, thin_trajectory
from shipgym_baselines.runs import light_trajectory

BUCKETS = 50


def _buckets(t: np.ndarray, buckets: int) -> np.ndarray:
    return np.minimum(((t - t[0]) / (t[-1] - t[0]) * buckets).astype(int), buckets - 1)


def test_every_bucket_keeps_the_signals_envelope_and_the_endpoints_are_kept() -> None:
    rng = np.random.default_rng(3)
    t = np.linspace(0.0, 1000.0, 20001)
    e = np.cumsum(rng.normal(size=t.size))  # a random walk: extremes anywhere
    rudder = np.clip(rng.normal(scale=0.5, size=t.size), -0.61, 0.61)
    index = m4_indices(t, [e, rudder], BUCKETS)
    assert index.size < t.size / 20
    assert index[0] == 0 and index[-1] == t.size - 1
    full, kept = _buckets(t, BUCKETS), _buckets(t[index], BUCKETS)
    for signal in (e, rudder):
        for b in range(BUCKETS):
            drawn = signal[index][kept == b]
            whole = signal[full == b]
            assert (drawn.min(), drawn.max()) == (whole.min(), whole.max())


def test_a_limit_cycle_at_the_bucket_scale_still_spans_its_amplitude() -> None:
    """A ±35° rudder limit cycle of 2 s period over 2000 s, sampled at 0.1 s (a stride of
    one sample in ten would draw it as a flat line)."""
    t = np.arange(0.0, 2000.0, 0.1)
    amplitude = np.radians(35.0)
    rudder = amplitude * np.sin(2 * np.pi * t / 2.0)
    thin = thin_trajectory({"t": t, "rudder_angle": rudder}, ("t", "rudder_angle"), BUCKETS)
    kept = _buckets(thin["t"], BUCKETS)
    for b in range(BUCKETS):
        drawn = thin["rudder_angle"][kept == b]
        assert drawn.max() > 0.99 * amplitude and drawn.min() < -0.99 * amplitude
    strided = rudder[::10]
    assert np.abs(strided).max() < 0.01 * amplitude  # what the stride would have drawn


def test_a_kept_trajectory_holds_the_drawn_arrays_only_and_short_ones_whole() -> None:
    t = np.arange(300) * 0.5
    trajectory = {k: np.sin(t + i) for i, k in enumerate(DRAWN_KEYS)}
    trajectory |= {"t": t, "heading": t, "rudder_command": t}
    light = light_trajectory(trajectory)
    assert tuple(light) == DRAWN_KEYS
    assert all(light[k].dtype == np.float32 and light[k].size == t.size for k in light)
    np.testing.assert_array_equal(light["x"], trajectory["x"].astype(np.float32))

"""The kept trajectories: M4 thinning (what a figure draws is what it would draw of the
full signal), packing, and a record's ``trajectory`` naming only a file inside its run
folder (``report`` never reads a file elsewhere)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import yaml

from shipgym_baselines.cli import main
from shipgym_baselines.errors import RunError
from shipgym_baselines.records.episodes import EPISODES_FILE
from shipgym_baselines.records.trajectories import (
    DRAWN_KEYS,
    episode_result,
    light_trajectory,
    m4_indices,
    pack_trajectory,
    read_trajectory,
    thin_trajectory,
    unpack_trajectory,
)

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
    assert set(light) == {"keys", "ranges", "codes"} and light["codes"].dtype == np.uint16
    kept = unpack_trajectory(light)
    assert tuple(kept) == DRAWN_KEYS and all(kept[k].size == t.size for k in kept)
    for key in DRAWN_KEYS:  # within range / 131068 of the drawn value
        span = np.ptp(trajectory[key])
        assert np.max(np.abs(kept[key] - trajectory[key])) <= span / 131068 * (1 + 1e-9)


def test_a_packed_trajectory_keeps_non_finite_values_constants_and_big_steps(
    tmp_path: Path,
) -> None:
    """The codes' differences wrap mod 2^16 and come back; NaN and ±inf read back as NaN
    where they were; a constant array is its value; the file reads back as written."""
    x = np.array([0.0, 6000.0, -3.5, np.nan, 12.25, np.inf, 6000.0])
    packed = pack_trajectory({"t": np.arange(7.0), "x": x, "c": np.full(7, 2.5)})
    np.savez_compressed(tmp_path / "a.npz", **packed)
    back = read_trajectory(tmp_path / "a.npz")
    finite = np.isfinite(x)
    assert np.array_equal(np.isnan(back["x"]), ~finite)
    assert np.max(np.abs(back["x"][finite] - x[finite])) <= 6003.5 / 131068 * (1 + 1e-9)
    assert back["x"][2] == -3.5  # the range's low end exactly
    np.testing.assert_array_equal(back["c"], np.full(7, 2.5))
    np.testing.assert_allclose(back["t"], np.arange(7.0), rtol=0, atol=6 / 131068)


def test_finding7_a_records_trajectory_names_only_a_file_in_its_run_folder(
    tmp_path: Path, capsys
) -> None:
    run = tmp_path / "run"
    suite = tmp_path / "one.yaml"
    suite.write_text(
        yaml.safe_dump(
            {"name": "one", "scenarios": ["nominal"], "controllers": ["zero_rudder"], "seeds": 1}
        )
    )
    assert (
        main(
            [
                "leaderboard",
                "--suite",
                str(suite),
                "--out",
                str(run),
                "--workers",
                "1",
                "--no-progress",
                "--no-references",
                "--json",
            ]
        )
        == 0
    )
    outside = tmp_path / "elsewhere.npz"
    np.savez(outside, t=np.arange(3.0))
    (record,) = [json.loads(line) for line in (run / EPISODES_FILE).read_text().splitlines()]
    for name in (str(outside), "../elsewhere.npz", "trajectories/../../elsewhere.npz"):
        with pytest.raises(RunError, match="not a file inside its run folder"):
            episode_result({**record, "trajectory": name}, run)
    (run / EPISODES_FILE).write_text(json.dumps({**record, "trajectory": str(outside)}) + "\n")
    capsys.readouterr()
    code = main(["report", str(run), "--out", str(tmp_path / "report")])
    err = capsys.readouterr().err.strip()
    assert code == 2 and "not a file inside its run folder" in err and len(err.splitlines()) == 1

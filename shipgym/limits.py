"""The documented limits of a run: what a scenario, a suite or a command line may ask for.

Values beyond them do not describe a ship task, they exhaust the machine (a 10¹² s episode
grows its log to gigabytes, a 10⁻⁷ s fine step unrolls millions of substeps, 10⁹ seeds
allocate before the first episode, a position of 10³⁰⁰ m leaves no precision for a
cross-track error).  Each is refused early, in one line naming the key and the limit.

* steps per episode, time_limit / control_period: :data:`MAX_EPISODE_STEPS` (``time_limit``);
* substeps per step, control_period / fine_step: :data:`MAX_SUBSTEPS` (``fine_step``, else
  ``control_period``);
* waypoints of a path: :data:`MAX_WAYPOINTS` (``path.waypoints``);
* a position [m], start or waypoint: ±:data:`MAX_POSITION_M` (``initial_state.x`` / ``y``,
  ``path.waypoints``);
* a config file (YAML): :data:`MAX_CONFIG_BYTES` bytes, refused before parsing;
* evaluation seeds per scenario: :data:`MAX_SEEDS` (``--seeds``, a suite's ``seeds``);
* held-out scenarios of a suite: :data:`MAX_HELDOUT_SCENARIOS` (``heldout_scenarios``);
* in-range scenarios of a suite: :data:`MAX_INRANGE_SCENARIOS` (``inrange_scenarios``);
* trial ranges of a suite's ``randomize:``: :data:`RANDOMIZE_BOUNDS` (``randomize.<key>``);
* local worker processes: at least 1, at most the number of jobs (more are clamped to it,
  :func:`worker_count`; ``--workers``).
"""

from __future__ import annotations

from shipgym.errors import ShipgymError

#: control periods of one episode (time_limit / control_period); the catalogue's longest: 4000
MAX_EPISODE_STEPS = 100_000
#: fine integration substeps per control period (control_period / fine_step); catalogue: ≤ 50
MAX_SUBSTEPS = 1_000
#: waypoints of a path; the catalogue's longest: 8
MAX_WAYPOINTS = 10_000
#: |coordinate| of a start or waypoint [m] (1000 km); the catalogue's farthest: 10 km
MAX_POSITION_M = 1.0e6
#: size of a scenario or suite YAML file [bytes] (10,000 waypoints take ≈ 300 kB)
MAX_CONFIG_BYTES = 1_000_000
#: evaluation seeds per scenario of a run
MAX_SEEDS = 10_000
#: held-out test scenarios a suite draws (``heldout_scenarios``); the default suite: 4
MAX_HELDOUT_SCENARIOS = 1_000
#: in-range test scenarios a suite draws (``inrange_scenarios``); the default suite: 16
MAX_INRANGE_SCENARIOS = 1_000
#: the interval each trial range of a suite's ``randomize:`` block must lie in
RANDOMIZE_BOUNDS: dict[str, tuple[float, float]] = {
    "cross_track_offset_L": (-100.0, 100.0),  # ship lengths
    "heading_error_deg": (-180.0, 180.0),
    "jump_time_jitter_s": (-3600.0, 3600.0),
    "current_speed_factor": (0.0, 10.0),
    "current_direction_deg": (-180.0, 180.0),
}


class LimitError(ShipgymError, ValueError):
    """A value beyond a documented limit (inside a config validator, the key is named)."""


def check_at_most(value: float, limit: float, what: str) -> None:
    """:class:`LimitError` unless ``value`` ≤ ``limit``, naming ``what`` and the limit."""
    if value > limit:
        raise LimitError(f"{what} is {value:.6g}, beyond the limit of {limit:.6g}")


def worker_count(workers: int, jobs: int, option: str = "--workers") -> int:
    """The local processes to start for ``jobs`` jobs: ``workers`` clamped to the jobs
    (at least 1); a ``workers`` below 1 is a :class:`LimitError` naming ``option``."""
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise LimitError(f"{option} must be a whole number ≥ 1, got {workers!r}")
    return max(1, min(workers, jobs))

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
* a config file (YAML): :data:`MAX_CONFIG_BYTES` bytes, refused before parsing; nested at
  most :data:`MAX_CONFIG_DEPTH` levels deep and at most :data:`MAX_CONFIG_NODES` values
  with its aliases expanded, refused while parsing;
* a scenario's or suite's ``name``: :data:`MAX_NAME_CHARS` characters, :data:`MAX_NAME_BYTES`
  bytes of UTF-8, no control character (:func:`name_problem`; file names are made of it);
* evaluation seeds per scenario: :data:`MAX_SEEDS` (``--seeds``, a suite's ``seeds``);
* held-out scenarios of a suite: :data:`MAX_HELDOUT_SCENARIOS` (``heldout_scenarios``);
* in-range scenarios of a suite: :data:`MAX_INRANGE_SCENARIOS` (``inrange_scenarios``);
* scenarios a suite lists: :data:`MAX_SUITE_SCENARIOS` (``scenarios``), refused before any
  of them is loaded;
* steps of history in a learned agent's observation: :data:`MAX_HISTORY_STEPS`
  (``history_steps``);
* a controller's own figures of an episode (``episode_stats``): at most
  :data:`MAX_CONTROLLER_STATS` entries, each text at most :data:`MAX_STAT_TEXT_CHARS`
  characters;
* a metric of an ``episodes.jsonl`` record: at most :data:`MAX_METRIC` in magnitude;
* trial ranges of a suite's ``randomize:``: :data:`RANDOMIZE_BOUNDS` (``randomize.<key>``);
* local worker processes: at least 1, at most the number of jobs (more are clamped to it,
  :func:`worker_count`; ``--workers``).
"""

from __future__ import annotations

import unicodedata

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
#: levels of nested mappings and lists in a YAML file; the catalogue's deepest: 10
MAX_CONFIG_DEPTH = 50
#: values (scalars, mappings, lists) of a YAML file with its aliases expanded; a file within
#: MAX_CONFIG_BYTES holds at most ≈ 500,000 without aliases
MAX_CONFIG_NODES = 1_000_000
#: characters of a scenario's or suite's name (a figure's file name is made of it)
MAX_NAME_CHARS = 100
#: bytes of a name in UTF-8: with a figure's prefix and suffix and a temporary's, the file
#: name stays within the 255 bytes file systems allow
MAX_NAME_BYTES = 200
#: evaluation seeds per scenario of a run
MAX_SEEDS = 10_000
#: held-out test scenarios a suite draws (``heldout_scenarios``); the default suite: 4
MAX_HELDOUT_SCENARIOS = 1_000
#: in-range test scenarios a suite draws (``inrange_scenarios``); the default suite: 16
MAX_INRANGE_SCENARIOS = 1_000
#: scenarios a suite lists (``scenarios``: names and YAML files); the default suite: 13
MAX_SUITE_SCENARIOS = 1_000
#: control steps of history a learned agent observes (``history_steps``): 1000 steps are
#: 17 min at the catalogue's 1 s control period, and 8 values a step
MAX_HISTORY_STEPS = 1_000
#: entries of a controller's ``episode_stats`` (the catalogue's most: 4)
MAX_CONTROLLER_STATS = 100
#: characters of a text value of a controller's ``episode_stats``
MAX_STAT_TEXT_CHARS = 300
#: magnitude of a metric of an episode record: no episode within these limits comes near it
#: (the corridor penalty is ≈ 10³), a value beyond is a damaged or forged record
MAX_METRIC = 1.0e30
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


def name_problem(name: str) -> str | None:
    """Why ``name`` cannot name a scenario or suite, or None: longer than
    :data:`MAX_NAME_CHARS` characters or :data:`MAX_NAME_BYTES` bytes (figures and their
    temporaries are files named after it), empty, or holding a control character, line
    break or lone surrogate (neither a file name nor a one-line message can carry it).
    Other characters are drawn as typed and become ``_`` in a file name."""
    if not name.strip():
        return "is empty"
    if len(name) > MAX_NAME_CHARS:
        return f"has {len(name)} characters, beyond the limit of {MAX_NAME_CHARS}"
    bad = next((c for c in name if unicodedata.category(c) in _UNPRINTABLE), None)
    if bad is not None:
        return f"holds the character U+{ord(bad):04X}, which no file name or line can carry"
    size = len(name.encode("utf-8"))
    if size > MAX_NAME_BYTES:
        return f"takes {size} bytes in UTF-8, beyond the limit of {MAX_NAME_BYTES}"
    return None


#: Unicode categories a name may not hold: control, surrogate, line and paragraph separator
_UNPRINTABLE = ("Cc", "Cs", "Zl", "Zp")


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

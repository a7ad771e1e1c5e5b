"""Run records: every ``leaderboard`` / ``evaluate`` run keeps its results in its ``--out``.

::

    run.json         command (argv), suite (resolved: seeds, randomize, controllers with
                     their training seeds, each scenario's settings by table name, the
                     files of the suite's own scenarios), versions, git commit,
                     start/end time (ISO 8601 UTC), status ("running" → "complete" |
                     "interrupted" | "failed"), jobs (the episodes the run holds when
                     complete), episodes, wall_s and cpu_s (wall-clock and CPU seconds
                     of the run, tables and figures included, its process and its
                     workers; a resumed run adds each invocation's)
    episodes.jsonl   one JSON object per finished episode (scenario, controller, kind, seed,
                     training_seed and every metric), appended and flushed by the parent
                     process as each episode ends: Ctrl-C or a kill keeps them; fsync'd at
                     most :data:`FSYNC_INTERVAL_S` apart and at the end (a power cut loses
                     at most that last second); an episode's key is (scenario, controller,
                     seed, training_seed)
    trajectories/    the drawn episodes' trajectories: each episode's is written as it
                     ends (``<hash of its key>.npz``, :func:`trajectory_file`), and once a
                     row (scenario, controller) is complete only the episode its figure
                     draws is kept (:meth:`RunLog.drop_trajectories`)

A run holds an exclusive lock on its folder (:mod:`shipgym_baselines.records.locking`) and
lists every path it writes in ``manifest.txt`` (:mod:`shipgym_baselines.records.manifest`),
each written through no link (:mod:`shipgym_baselines.records.outfiles`; a folder holding a
link is refused).  A folder that is not empty is refused before any work unless ``resume``
(run the episodes missing from ``episodes.jsonl``; the resolved suite must equal
``run.json``'s) or ``force`` (delete what the manifest lists first; a folder holding anything
else is refused).  ``episodes.jsonl`` is read as a set keyed by the episode key
(:func:`read_episodes`).  Tables are always aggregated from ``episodes.jsonl`` (so a resumed
run's tables equal a clean run's, and ``shipgym report`` rebuilds them from the folder).

Strict JSON has no infinity or NaN: in ``episodes.jsonl`` a metric of ±inf (t_c = inf, "never
converged") is the string ``"inf"`` / ``"-inf"`` and NaN is ``null`` (metrics ignore NaN), so
a record reads back to the same numbers (:func:`read_episodes`).  Read back, each value is
checked by type: a metric is a finite number, null, ``"inf"`` or ``"-inf"``; only
:data:`BOOL_METRICS` are booleans and :data:`TEXT_METRICS` text.

The code lives in the modules named for what they hold, and this module re-exports their
names: the output folder (:mod:`~shipgym_baselines.records.folders`), ``run.json``
(:mod:`~shipgym_baselines.records.runrecord`), JSON files and strict-JSON metrics
(:mod:`~shipgym_baselines.records.jsonfiles`), episode records and ``episodes.jsonl``
(:mod:`~shipgym_baselines.records.episodes`), kept trajectories
(:mod:`~shipgym_baselines.records.trajectories`) and the open run
(:mod:`~shipgym_baselines.records.runlog`).
"""

from __future__ import annotations

from shipgym_baselines.executor import BACKENDS  # the backends of --backend, public here too
from shipgym_baselines.records.episodes import (
    BOOL_METRICS,
    EPISODE_KEYS,
    EPISODES_FILE,
    TEXT_METRICS,
    Key,
    episode_key,
    episode_record,
    read_episodes,
)
from shipgym_baselines.records.folders import check_out_dir, check_out_usable, clear_outputs
from shipgym_baselines.records.jsonfiles import (
    as_json,
    differences,
    from_plain,
    plain,
    write_json,
)
from shipgym_baselines.records.runlog import (
    FSYNC_INTERVAL_S,
    NO_ROOM,
    RunInterrupted,
    RunLog,
    cpu_seconds,
    outside_problem,
)
from shipgym_baselines.records.runrecord import (
    PACKAGES,
    RUN_FILE,
    git_commit,
    now,
    read_run,
    versions,
)
from shipgym_baselines.records.trajectories import (
    TRAJECTORY_DIR,
    episode_result,
    light_trajectory,
    read_trajectory,
    trajectory_file,
)

__all__ = [
    "BACKENDS",
    "BOOL_METRICS",
    "EPISODES_FILE",
    "EPISODE_KEYS",
    "FSYNC_INTERVAL_S",
    "NO_ROOM",
    "PACKAGES",
    "RUN_FILE",
    "TEXT_METRICS",
    "TRAJECTORY_DIR",
    "Key",
    "RunInterrupted",
    "RunLog",
    "as_json",
    "check_out_dir",
    "check_out_usable",
    "clear_outputs",
    "cpu_seconds",
    "differences",
    "episode_key",
    "episode_record",
    "episode_result",
    "from_plain",
    "git_commit",
    "light_trajectory",
    "now",
    "outside_problem",
    "plain",
    "read_episodes",
    "read_run",
    "read_trajectory",
    "trajectory_file",
    "versions",
    "write_json",
]

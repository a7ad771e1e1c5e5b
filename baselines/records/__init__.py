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
                     most :data:`~.runlog.FSYNC_INTERVAL_S` apart and at the end (a power cut loses
                     at most that last second); an episode's key is (scenario, controller,
                     seed, training_seed)
    trajectories/    the drawn episodes' trajectories: each episode's is written as it
                     ends (``<hash of its key>.npz``,
                     :func:`~.trajectories.trajectory_file`), and once a row (scenario,
                     controller) is complete only the episode its figure draws is kept
                     (:meth:`~.runlog.RunLog.drop_trajectories`)

A run holds an exclusive lock on its folder (:mod:`shipgym_baselines.records.locking`) and
lists every path it writes in ``manifest.txt`` (:mod:`shipgym_baselines.records.manifest`),
each written through no link (:mod:`shipgym_baselines.records.outfiles`; a folder holding a
link is refused).  A folder that is not empty is refused before any work unless ``resume``
(run the episodes missing from ``episodes.jsonl``; the resolved suite must equal
``run.json``'s) or ``force`` (delete what the manifest lists first; a folder holding anything
else is refused).  ``episodes.jsonl`` is read as a set keyed by the episode key
(:func:`~.episodes.read_episodes`).  Tables are always aggregated from ``episodes.jsonl``
(so a resumed run's tables equal a clean run's, and ``shipgym report`` rebuilds them from
the folder).

Strict JSON has no infinity or NaN: in ``episodes.jsonl`` a metric of ±inf (t_c = inf, "never
converged") is the string ``"inf"`` / ``"-inf"`` and NaN is ``null`` (metrics ignore NaN), so
a record reads back to the same numbers (:func:`~.episodes.read_episodes`).  Read back, each
value is checked by type: a metric is a finite number, null, ``"inf"`` or ``"-inf"``; only
:data:`~.episodes.BOOL_METRICS` are booleans and :data:`~.episodes.TEXT_METRICS` text.

Each module is named for what it holds: the output folder
(:mod:`~shipgym_baselines.records.folders`), ``run.json``
(:mod:`~shipgym_baselines.records.runrecord`), JSON files and strict-JSON metrics
(:mod:`~shipgym_baselines.records.jsonfiles`), episode records and ``episodes.jsonl``
(:mod:`~shipgym_baselines.records.episodes`), kept trajectories
(:mod:`~shipgym_baselines.records.trajectories`), the open run
(:mod:`~shipgym_baselines.records.runlog`), the list of files a run wrote
(:mod:`~shipgym_baselines.records.manifest`), the lock on its folder
(:mod:`~shipgym_baselines.records.locking`), writes through no link
(:mod:`~shipgym_baselines.records.outfiles`), the trials a run deals
(:mod:`~shipgym_baselines.records.trials`) and the chosen settings
(:mod:`~shipgym_baselines.records.chosen`).
"""

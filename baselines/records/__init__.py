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

The modules: what a run leaves on disk: an episode's result and its line of ``episodes.jsonl``
(:mod:`~shipgym_baselines.records.episodes`), the run's record ``run.json``
(:mod:`~shipgym_baselines.records.runrecord`), the open run that appends to them
(:mod:`~shipgym_baselines.records.runlog`), whether ``--out`` can hold a run
(:mod:`~shipgym_baselines.records.folders`), its JSON files
(:mod:`~shipgym_baselines.records.jsonfiles`), the list of files it wrote
(:mod:`~shipgym_baselines.records.manifest`), the lock on its folder
(:mod:`~shipgym_baselines.records.locking`), writes through no link
(:mod:`~shipgym_baselines.records.outfiles`) and the thinned, packed trajectories its figures
draw (:mod:`~shipgym_baselines.records.trajectories`).
"""

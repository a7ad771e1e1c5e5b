"""What a run leaves on disk: an episode's result (:mod:`~shipgym_baselines.records.episodes`),
the run's record (``run.json``, ``episodes.jsonl``: :mod:`~shipgym_baselines.records.runs`),
the list of files it wrote (:mod:`~shipgym_baselines.records.manifest`), the lock on its
folder (:mod:`~shipgym_baselines.records.locking`), writes through no link
(:mod:`~shipgym_baselines.records.outfiles`) and the thinned, packed trajectories its figures
draw (:mod:`~shipgym_baselines.records.trajectories`)."""

"""What a run leaves on disk (:mod:`~shipgym_baselines.records.runs`: the run folder, and
every name of these modules): an episode's result and its line of ``episodes.jsonl``
(:mod:`~shipgym_baselines.records.episodes`), the run's record ``run.json``
(:mod:`~shipgym_baselines.records.runrecord`), the open run that appends to them
(:mod:`~shipgym_baselines.records.runlog`), whether ``--out`` can hold a run
(:mod:`~shipgym_baselines.records.folders`), its JSON files
(:mod:`~shipgym_baselines.records.jsonfiles`), the list of files it wrote
(:mod:`~shipgym_baselines.records.manifest`), the lock on its folder
(:mod:`~shipgym_baselines.records.locking`), writes through no link
(:mod:`~shipgym_baselines.records.outfiles`) and the thinned, packed trajectories its figures
draw (:mod:`~shipgym_baselines.records.trajectories`)."""

"""The leaderboard: every controller on every suite scenario × seeds, one table.

Each evaluation seed runs its own trial of a scenario: the suite's ``randomize`` ranges
(:mod:`shipgym.scenarios.trials`) draw the start, the jump time and the current from the
seed, and the sensor noise varies with it too.  A learned agent runs once per training seed
(:func:`shipgym_baselines.registry.training_seeds`), so its row aggregates training seeds ×
evaluation seeds.

The work is cut into jobs (:class:`~shipgym_baselines.leaderboard.jobs.Job`: the
controller's resolved record, scenario names and seeds; the worker builds each seed's
trial): a classical controller's job is one scenario for all the evaluation seeds, a learned
agent's one training seed on one scenario for all of them, the oracle's one (scenario, seed)
trial; a job's seeds run in lockstep (:func:`shipgym_baselines.evaluation.evaluate_batch`:
the rows of one evaluation trials env, one network forward per step for a learned agent's,
equal to the episodes one by one). ``local`` runs the jobs in a process pool; ``ray``
submits the same job function to a Ray cluster (``pip install shipgym[ray]``). The parent
records each episode as it arrives (:mod:`shipgym_baselines.records`: ``run.json``,
``episodes.jsonl``), and every table is aggregated from that record: the rows with
``*_ci95`` intervals, ``aggregate.json`` (the ranking of
:mod:`shipgym_baselines.scoring.ranking`: cost over the oracle's), ``scenario_scores.json``,
the figures."""

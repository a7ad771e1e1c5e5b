"""One-off studies run beside the leaderboard: the speed benchmarks
(:mod:`~shipgym_baselines.studies.benchmarks`), where a leaderboard run's CPU time goes
(:mod:`~shipgym_baselines.studies.run_costs`), whether a scenario's change matters
(:mod:`~shipgym_baselines.studies.change_effect`) and what each unit reading does
(:mod:`~shipgym_baselines.studies.unit_readings`)."""

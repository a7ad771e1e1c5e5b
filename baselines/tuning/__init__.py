"""One tuning protocol for every tunable controller, classical and learned (docs/tuning.md).

``shipgym tune NAME`` (:mod:`shipgym_baselines.cli.tune`) runs an Optuna study whose search
space, budget and validation trials are ``configs/tuning/<NAME>.yaml``
(:mod:`~shipgym_baselines.tuning.space`); its objective is the leaderboard's cost ratio to
the ``oracle`` on the validation split only (:mod:`~shipgym_baselines.tuning.validation`,
:mod:`~shipgym_baselines.tuning.objective`); the study, its report and the chosen settings
are :mod:`~shipgym_baselines.tuning.study`, :mod:`~shipgym_baselines.tuning.report` and
:mod:`~shipgym_baselines.tuning.chosen`.  The protocol is written down in ``docs/tuning.md``.
"""

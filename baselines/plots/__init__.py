"""The leaderboard's figures: per-scenario small multiples, the rliable ranking and the
performance profiles, the learning curves, one look per controller, and the files they are
written to.

Every figure uses :func:`~shipgym_baselines.plots.style.controller_style` (one colour and
line style per controller, the same in every figure), labels its axes with units, keeps
legends outside the data and is written by :func:`~shipgym_baselines.plots.files.save_figure`:
drawn at :data:`~shipgym_baselines.plots.style.FIGURE_DPI` (200 dpi) and written as a palette
PNG of at most :data:`~shipgym_baselines.plots.files.PAGE_WIDTH` pixels (the page's image);
only when asked (``vector``, the ``--vector-figures`` option), also as a vector copy beside
it (SVG; the scenario figures, which hold the long trajectories, as gzip-compressed SVGZ).
Matplotlib runs on the Agg backend.

What a run hands in:

* ``drawn``: (scenario, controller) → :class:`~shipgym_baselines.plots.scenarios.DrawnEpisode`
  (or a plain ``(seed, trajectory)`` / ``(seed, trajectory, training_seed)`` tuple): the
  episode to draw, its trajectory as an episode result keeps it (arrays ``t`` [s], ``x``,
  ``y`` [m], ``cross_track_error`` [m], ``rudder_angle`` [rad], …).
  :func:`~shipgym_baselines.plots.scenarios.median_ace_episode` names the episode to keep
  (the median-ACE seed, and its training seed);
  :func:`~shipgym_baselines.plots.scenarios.episodes_to_draw` picks them from episode results.
* ``aggregate``: the ``aggregate.json`` rows
  (:func:`~shipgym_baselines.scoring.ranking.aggregate_ranking`); ``episodes``: the
  ``episodes.jsonl`` records; ``splits``: scenario → split.

The figures (each function returns the written files, the PNG then any vector copy):

* :func:`~shipgym_baselines.plots.scenarios.plot_scenario`: one scenario, a grid with one
  column per controller family (at most
  :data:`~shipgym_baselines.plots.panels.PANEL_CONTROLLERS` controllers a column) and three
  rows with the same axes in every column: track x–y over the path, e(t), δ(t); the oracle's
  episode drawn in every column as the reference, and the frozen optimum's
  (``oracle_frozen``, dash-dotted, "never adapts"); the parameter-change time as a labelled
  vertical line and each ship's position at that time.  File ``scenario_<name>``.
  :func:`~shipgym_baselines.plots.scenarios.plot_scenarios` draws every scenario of
  ``drawn``.
* :func:`~shipgym_baselines.plots.ranking.plot_ranking`: per split, rliable's interval
  estimates (IQM and geometric mean of the cost ratio C / C_oracle on a log axis,
  P(improvement over pid_los) and the failure rate, 95 % intervals; the frozen optimum's
  IQM and geometric mean as a dash-dotted line; file ``ranking_<split>``) and performance
  profiles of the cost ratio (one panel per family, file ``profile_<split>``).
* :func:`~shipgym_baselines.plots.curves.plot_learning_curves`: the learned agents'
  learning curves.

18 scenarios and the ranking of 20 controllers take about half a minute on one core.
"""

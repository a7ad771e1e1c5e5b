"""The leaderboard's figures: per-scenario small multiples and the rliable ranking.

Every figure uses :func:`shipgym_baselines.plots.style.controller_style` (one colour and line
style per controller, the same in every figure), labels its axes with units, keeps legends
outside the data and is written by :func:`save_figure`: drawn at
:data:`~shipgym_baselines.plots.style.FIGURE_DPI` (200 dpi) and written as a palette PNG
of at most :data:`PAGE_WIDTH` pixels (the page's image); only when asked (``vector``, the
``--vector-figures`` option), also as a vector copy beside it (SVG; the scenario figures,
which hold the long trajectories, as gzip-compressed SVGZ).  Matplotlib runs on the Agg
backend.

What a run hands in:

* ``drawn``: (scenario, controller) → :class:`DrawnEpisode` (or a plain ``(seed,
  trajectory)`` / ``(seed, trajectory, training_seed)`` tuple) — the episode to draw, its
  trajectory as :attr:`shipgym_baselines.records.episodes.EpisodeResult.trajectory` keeps it
  (arrays ``t`` [s], ``x``, ``y`` [m], ``cross_track_error`` [m], ``rudder_angle`` [rad], …).
  :func:`median_ace_episode` names the episode to keep (the median-ACE seed, and its training
  seed), :func:`episodes_to_draw` picks them from episode results.
* ``aggregate``: the ``aggregate.json`` rows
  (:func:`shipgym_baselines.scoring.ranking.aggregate_ranking`);
  ``episodes``: the ``episodes.jsonl`` records; ``splits``: scenario → split.

Functions (each returns the written files, the PNG then any vector copy):

* :func:`plot_scenario` ``(out_dir, scenario, drawn, change_time, path_xy=None,
  ship_length=None, kinds=None, chosen_by="median-ACE")`` — one scenario: a grid with one
  column per controller family (at most :data:`PANEL_CONTROLLERS` controllers a column) and
  three rows with the same axes in every column: track x–y over the path, e(t), δ(t); the
  oracle's episode (controller ``oracle``) drawn in every column as the reference, and the
  frozen optimum's (``oracle_frozen``, dash-dotted, "never adapts"); the
  parameter-change time as a labelled vertical line ("change at t = … s") and each ship's
  position at that time; the title and legends say which episode is drawn.  File
  ``scenario_<name>``.
* :func:`plot_scenarios` ``(out_dir, drawn, scenarios=None, kinds=None,
  chosen_by="median-ACE")`` — every scenario of ``drawn``; change time, path and ship
  length read from the scenario (:func:`shipgym.scenarios.load_scenario` of
  ``scenarios[name]``, else of the name).
* :func:`plot_ranking` ``(out_dir, aggregate, episodes, splits, kinds=None)`` — per split: rliable's
  interval estimates (IQM and geometric mean of the cost ratio C / C_oracle on a log axis,
  P(improvement over pid_los) and the failure rate, 95 % intervals; with the frozen
  optimum's episodes, a dash-dotted line on each cost-ratio panel where it lies: the IQM
  and the geometric mean of its ratios C_frozen / C_oracle over the split's trials; file
  ``ranking_<split>``) and performance profiles of the cost ratio (one panel per family,
  file ``profile_<split>``).

18 scenarios and the ranking of 20 controllers take about half a minute on one core.
"""

from __future__ import annotations


# each kind of figure has its module (scenario_figures, ranking_figures, curve_figures; what
# they share: panels, figure_files); their names stay importable from here

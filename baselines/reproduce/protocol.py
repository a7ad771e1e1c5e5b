"""The common shape of a paper reproduction (``shipgym reproduce PAPER``, docs/reproduction.md).

Every paper is a package ``shipgym_baselines.reproduce.<paper>`` with the same parts:

* ``experiment.run_experiment(seeds, progress, **options) -> Outcome``: the episodes and the
  rows (:func:`shipgym_baselines.reproduce.rows.reproduction_row`); no files;
* ``claims`` where the paper states something checkable: rows whose ``paper`` is the claim;
* ``tables.report(rows) -> str``: the markdown report, its tables made by
  :func:`shipgym_baselines.reproduce.report.table`;
* ``figures.plots(outcome, out_dir)``: the figures, from the outcome's episodes;

joined by one :class:`Reproduction` (the package's ``REPRODUCTION``), whose :meth:`run`
writes ``<name>.json``, ``<name>.md``, the outcome's extra documents and the figures;
:mod:`shipgym_baselines.cli` calls its ``run`` and ``markdown`` through
:data:`shipgym_baselines.reproduce.PAPERS`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from pathlib import Path
from typing import Any

from shipgym_baselines.jsonout import dumps
from shipgym_baselines.records.outfiles import write_text

#: the rows a reproduction reports (its --json): ``{case, controller, metric, ours, paper, …}``
Rows = list[dict[str, Any]]
#: called once per unit of work (an episode, a noise realisation)
Progress = Callable[[], object]


@dataclasses.dataclass
class Outcome:
    """What one experiment produced: its rows, what the figures need, extra documents."""

    rows: Rows
    episodes: Any = None  # paper-specific (e.g. first-seed episodes per case and controller)
    documents: dict[str, Any] = dataclasses.field(default_factory=dict)  # file name -> JSON


@dataclasses.dataclass(frozen=True)
class Reproduction:
    """One paper's reproduction: its id and the three steps of the module doc."""

    name: str  # paper id, e.g. "xu2021": the CLI's choice and the output file stem
    run_experiment: Callable[..., Outcome]  # (seeds, progress, **options) -> Outcome
    report: Callable[[Rows], str]  # rows -> markdown
    plots: Callable[[Outcome, Path], None]  # (outcome, out_dir) -> figures written

    def run(
        self,
        out_dir: str | Path | None = None,
        seeds: int = 1,
        progress: Progress | None = None,
        plot: bool = True,
        **options: Any,
    ) -> Rows:
        """Run the experiment and write its report into ``out_dir`` (default
        ``results/reproduce/<name>``); returns the rows.  ``options`` go to
        :attr:`run_experiment` (e.g. a shorter ``time_limit``)."""
        outcome = self.run_experiment(seeds=seeds, progress=progress, **options)
        out = Path(out_dir if out_dir is not None else f"results/reproduce/{self.name}")
        out.mkdir(parents=True, exist_ok=True)
        documents = {f"{self.name}.json": outcome.rows, **outcome.documents}
        for file_name, document in documents.items():
            write_text(out / file_name, dumps(document, indent=2))
        write_text(out / f"{self.name}.md", self.report(outcome.rows))
        if plot:
            self.plots(outcome, out)
        return outcome.rows

    def markdown(self, rows: Rows) -> str:
        """The markdown report of ``rows`` (:attr:`report`)."""
        return self.report(rows)

"""Re-runs of the source papers' experiments (``shipgym reproduce PAPER``, docs/reproduction.md).

One package per paper, each with the parts of :mod:`shipgym_baselines.reproduce.protocol` (the
experiment, its claims, the markdown report, the figures) joined in its ``REPRODUCTION``;
the rows are :func:`shipgym_baselines.reproduce.rows.reproduction_row`'s, the tables
:mod:`shipgym_baselines.reproduce.report`'s.
"""

from shipgym_baselines.reproduce import borkowski2018, liu2019, morenosalinas2013, xu2020, xu2021

#: paper id -> its package's ``REPRODUCTION`` (a :class:`~.protocol.Reproduction`), what
#: :mod:`shipgym_baselines.cli` calls: ``run(out_dir, seeds, progress) -> rows`` (writes the
#: report) and ``markdown(rows) -> str``
PAPERS = {
    package.REPRODUCTION.name: package.REPRODUCTION
    for package in (liu2019, morenosalinas2013, borkowski2018, xu2020, xu2021)
}

__all__ = [
    "PAPERS",
]

"""Re-runs of the source papers' experiments (``shipgym reproduce PAPER``)."""

from baselines.reproduce import borkowski2018, liu2019, morenosalinas2013, xu2020, xu2021

#: paper id -> module with ``run(out_dir, seeds) -> rows``
PAPERS = {
    "liu2019": liu2019,
    "morenosalinas2013": morenosalinas2013,
    "borkowski2018": borkowski2018,
    "xu2020": xu2020,
    "xu2021": xu2021,
}

__all__ = ["PAPERS"]

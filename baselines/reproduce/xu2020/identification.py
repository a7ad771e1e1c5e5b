"""Xu & Guedes Soares (2020) §5: the 20/20 zig-zag Nomoto fit and the Vyshnegradsky gains."""

from __future__ import annotations

from typing import Any

from shipgym.autopilot import vyshnegradsky_gains
from shipgym.identification.zigzag import ship_nomoto
from shipgym_baselines.reproduce.rows import reproduction_row
from shipgym_baselines.reproduce.xu2020.controllers import GAINS
from shipgym_baselines.reproduce.xu2020.published import PUBLISHED_GAINS, PUBLISHED_NOMOTO
from shipgym_baselines.reproduce.xu2020.scenarios import build_scenario


def setting_row(
    case: str,
    controller: str,
    metric: str,
    ours: float,
    paper: float | None,
    setting: str,
    gains: str | None,
    seeds: int,
    std: float | None = None,
) -> dict[str, Any]:
    """A reproduction row with the plant ``setting`` and the ``gains`` design (None: none)."""
    return reproduction_row(
        case, controller, metric, float(ours), paper, seeds, std, setting=setting, gains=gains
    )


def identification_rows(settings: tuple[str, ...], gains: tuple[str, ...]) -> list[dict]:
    """Nomoto fit of each setting's 20/20 zig-zag and its Vyshnegradsky gains (§5), plus the
    gains of the paper's own Nomoto model through the same design (setting ``paper_model``)."""
    rows: list[dict[str, Any]] = []
    models = {"paper_model": None}
    models.update({s: build_scenario("straight", s).model for s in settings})
    for setting, model in models.items():
        if model is None:
            nomoto = dict(PUBLISHED_NOMOTO)
        else:
            fit, _ = ship_nomoto(model)
            nomoto = {"K": fit.K, "T1": fit.T1, "T2": fit.T2, "T3": fit.T3}
            for key, value in nomoto.items():
                rows.append(
                    setting_row(
                        "zigzag_20_20",
                        "lssvm_nomoto2",
                        key,
                        value,
                        PUBLISHED_NOMOTO[key],
                        setting,
                        None,
                        1,
                    )
                )
        for label in gains:
            A, B = GAINS[label]
            g = vyshnegradsky_gains(*(nomoto[k] for k in ("K", "T1", "T2", "T3")), A=A, B=B)
            printed = PUBLISHED_GAINS.get(label, {})
            for key in ("kp", "kd", "ki"):
                rows.append(
                    setting_row(
                        "vyshnegradsky",
                        "pid",
                        key,
                        getattr(g, key),
                        printed.get(key),
                        setting,
                        label,
                        1,
                    )
                )
    return rows

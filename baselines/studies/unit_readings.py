"""Evidence for the nomoto2 unit reading: pid_los on each scenario under each reading.

``python -m shipgym_baselines.studies.unit_readings [--json]`` prints ACE, t_c and how the
episode ended for every catalogue nomoto2 scenario with ``ship.unit_reading`` set to each
reading (README, "Units of the nomoto2 ship").
"""

from __future__ import annotations

import argparse
import json

from shipgym.models.nomoto2 import UnitReading
from shipgym_baselines.evaluation import EVAL_SEED_OFFSET, evaluate
from shipgym_baselines.reproduce.variants import scenario_variant

SCENARIOS = ("nominal", "rudder_aging", "current_shift", "maneuverability_change")


def sweep(controller: str = "pid_los", seed: int = EVAL_SEED_OFFSET) -> list[dict]:
    rows = []
    for name in SCENARIOS:
        for reading in UnitReading:
            (result,) = evaluate(controller, scenario_variant(name, reading.value), [seed])
            m = result.metrics
            rows.append(
                {
                    "scenario": name,
                    "unit_reading": reading.value,
                    "ace": m["ace"],
                    "t_c": m["t_c"],
                    "max_abs_cross_track": m["max_abs_cross_track"],
                    "termination_reason": m["termination_reason"],
                }
            )
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    rows = sweep()
    if args.json:
        print(json.dumps(rows))
        return
    for r in rows:
        print(
            f"{r['scenario']:24s} {r['unit_reading']:15s} ACE {r['ace']:.3f} m  "
            f"t_c {r['t_c']:.1f} s  max|e| {r['max_abs_cross_track']:.2f} m  "
            f"{r['termination_reason']}"
        )


if __name__ == "__main__":
    main()

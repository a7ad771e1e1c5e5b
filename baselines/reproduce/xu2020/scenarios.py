"""Xu & Guedes Soares (2020) §6: the two cases (straight, curved) on three plant settings."""

from __future__ import annotations

from typing import Any

from shipgym.scenarios.loader import load_scenario

BASE_SCENARIO = "osaka_curved"
CASES = {  # case -> (path type, the paper's section and table)
    "straight": ("waypoints", "§6.1, Table 2"),
    "curved": ("pchip", "§6.2, Table 3"),
}
#: Xu & Guedes Soares (2020) §6.2: "The initial velocity ... is V = 0.1 m/s" [m/s]
CURVED_INITIAL_SPEED = 0.1
#: rudder rate limit of ``literal_no_rate_limit`` [rad/s, full scale]: no limit in effect
NO_RATE_LIMIT = 100.0
SETTINGS: dict[str, tuple[str, dict[str, float]]] = {  # name -> (variant, ship params)
    "literal": ("literal", {}),
    "literal_no_rate_limit": ("literal", {"rudder_rate": NO_RATE_LIMIT}),
    "intended_fix": ("intended_fix", {}),
}


def build_scenario(
    case: str,
    setting: str = "literal",
    time_limit: float | None = None,
    curved_initial_speed: float | None = CURVED_INITIAL_SPEED,
    current_speed: float | None = None,
) -> Any:
    """The scenario of one case on one plant setting (module doc).

    ``time_limit`` [s] (None: the base scenario's); ``curved_initial_speed`` [m/s] (None:
    cruise speed); ``current_speed`` [m/s] (None: the base scenario's current).
    """
    if case not in CASES:
        raise ValueError(f"unknown case {case!r}; valid: {list(CASES)}")
    if setting not in SETTINGS:
        raise ValueError(f"unknown setting {setting!r}; valid: {list(SETTINGS)}")
    path_type, where = CASES[case]
    variant, params = SETTINGS[setting]
    overrides: dict[str, Any] = {
        "source": f"Xu & Guedes Soares (2020) {where} (route and current assumed)",
        "path": {"type": path_type},
        "ship": {"variant": variant, "params": params},
    }
    if case == "curved" and curved_initial_speed is not None:
        overrides["initial_state"] = {"states": {"u": float(curved_initial_speed)}}
    if time_limit is not None:
        overrides["time_limit"] = float(time_limit)
    if current_speed is not None:
        overrides["disturbances"] = {"current": {"speed": float(current_speed)}}
    return load_scenario(BASE_SCENARIO).with_overrides(overrides, name=f"xu2020_{case}")

"""Variants of catalogue scenarios (another unit reading, no sensor noise) for experiments."""

from __future__ import annotations

from typing import Any

from shipgym.scenarios.loader import Scenario, load_scenario


def scenario_variant(
    name: str, unit_reading: str | None = None, noise_free: bool = False
) -> Scenario:
    """Catalogue scenario ``name`` with its ship's unit reading replaced and/or no sensor model
    (named ``name[unit_reading,noise_free]``)."""
    scenario = load_scenario(name)
    overrides: dict[str, Any] = {}
    drop: list[str] = []
    tags: list[str] = []
    if unit_reading is not None:
        overrides["ship"] = {"unit_reading": unit_reading}
        tags.append(unit_reading)
    if noise_free:
        drop.append("sensors")
        tags.append("noise_free")
    if not tags:
        return scenario
    return scenario.with_overrides(overrides, name=f"{name}[{','.join(tags)}]", drop=drop)

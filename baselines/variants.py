"""Variants of catalogue scenarios (another unit reading, no sensor noise) for experiments."""

from __future__ import annotations

import copy
from typing import Any

import yaml

from shipgym.scenarios import Scenario, catalogue_dir, scenario_from_dict


def scenario_variant(
    name: str, unit_reading: str | None = None, noise_free: bool = False
) -> Scenario:
    """Catalogue scenario ``name`` with its ship's unit reading replaced and/or no sensor model."""
    data: dict[str, Any] = yaml.safe_load((catalogue_dir() / f"{name}.yaml").read_text())
    data = copy.deepcopy(data)
    tags = []
    if unit_reading is not None:
        data.setdefault("ship", {})["unit_reading"] = unit_reading
        tags.append(unit_reading)
    if noise_free:
        data.pop("sensors", None)
        tags.append("noise_free")
    if tags:
        data["name"] = f"{name}[{','.join(tags)}]"
    return scenario_from_dict(data, data["name"])

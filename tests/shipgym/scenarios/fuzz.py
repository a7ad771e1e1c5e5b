"""A seeded fuzzer of scenario files: catalogue scenarios with a few numbers changed.

Each file is a catalogue scenario whose numeric leaves (ship parameters, start, path,
guidance, events, times, reward, disturbances) are changed at random: scaled by 10^U(−3, 3),
negated, set to 0 or to a small integer.  Used by the property test that every file
``shipgym scenarios --validate`` accepts makes an env that steps."""

from __future__ import annotations

import copy
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from shipgym.scenarios.loader import catalogue_dir, list_scenarios


def _leaves(data: Any, path: tuple = ()) -> Iterator[tuple[tuple, float]]:
    """(path, value) of every numeric leaf (not bools) of a YAML document."""
    if isinstance(data, dict):
        for key, value in data.items():
            yield from _leaves(value, (*path, key))
    elif isinstance(data, list):
        for i, value in enumerate(data):
            yield from _leaves(value, (*path, i))
    elif isinstance(data, int | float) and not isinstance(data, bool):
        yield path, float(data)


def _set(data: Any, path: tuple, value: float) -> None:
    for part in path[:-1]:
        data = data[part]
    if isinstance(data, tuple):  # never: YAML gives lists
        raise TypeError(path)
    data[path[-1]] = value


def _mutated(value: float, rng: np.random.Generator) -> float:
    how = rng.integers(5)
    if how == 0:
        return value * 10.0 ** rng.uniform(-3, 3)
    if how == 1:
        return -value
    if how == 2:
        return 0.0
    if how == 3:
        return float(rng.integers(-3, 4))
    return value * rng.uniform(0.5, 2.0)


def fuzzed_scenarios(n: int, seed: int) -> Iterator[dict[str, Any]]:
    """``n`` fuzzed scenario documents (1–3 numbers changed each), reproducible by seed."""
    rng = np.random.default_rng(seed)
    names = list_scenarios()
    sources = {
        name: yaml.safe_load(catalogue_dir().joinpath(f"{name}.yaml").read_text()) for name in names
    }
    for _ in range(n):
        data = copy.deepcopy(sources[names[rng.integers(len(names))]])
        leaves = list(_leaves(data))
        if rng.random() < 0.5:  # half the files: the ship's own numbers (its nominal model)
            leaves = [leaf for leaf in leaves if leaf[0][:1] == ("ship",)] or leaves
        for index in rng.choice(
            len(leaves), size=min(len(leaves), rng.integers(1, 4)), replace=False
        ):
            path, value = leaves[index]
            _set(data, path, _mutated(value, rng))
        yield data


def write_fuzzed(folder: Path, n: int, seed: int) -> list[Path]:
    """The fuzzed documents as YAML files in ``folder``."""
    files = []
    for i, data in enumerate(fuzzed_scenarios(n, seed)):
        file = folder / f"fuzz_{seed}_{i}.yaml"
        file.write_text(yaml.safe_dump(data, sort_keys=False))
        files.append(file)
    return files

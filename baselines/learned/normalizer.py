"""Observation normalisation statistics as data: ``vecnormalize.json``.

SB3 keeps a ``VecNormalize``'s statistics as a pickle (``vecnormalize.pkl``), and
unpickling runs any code the file holds.  A scoring run needs only the observation
statistics, so they live in JSON: ``norm_obs``, ``mean`` and ``var`` (one number per
observation entry, float64), ``epsilon`` and ``clip_obs``; :meth:`ObsNormalizer.normalize_obs`
is SB3's ``VecNormalize.normalize_obs`` on them, bit for bit (tested).

``python -m shipgym_baselines.learned.normalizer FILE.pkl`` converts a ``vecnormalize.pkl`` you
trust into ``vecnormalize.json`` beside it (that one unpickling is yours to allow).
"""

from __future__ import annotations

import json
import math
import pickle
import sys
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from shipgym.config import validate_model
from shipgym.envs.core import HISTORY_WIDTH, observation_names
from shipgym_baselines.errors import ControllerError
from shipgym_baselines.learned.trust import pickle_trusted, refuse_unpickling
from shipgym_baselines.records.outfiles import write_text

#: the lengths an observation can have: without and with the controller-context features
OBSERVATION_SIZES = (len(observation_names(False)), len(observation_names(True)))
#: the data file of the statistics, and the pickle SB3 writes (read only when trusted)
NORMALIZER_FILE = "vecnormalize.json"
PICKLED_NORMALIZER_FILE = "vecnormalize.pkl"


class ObsNormalizer(BaseModel):
    """Observation statistics of a ``VecNormalize``: ``mean`` and ``var`` per observation
    entry (in the observation's scaled units; the env's observation, or with the
    controller-context features after it), ``epsilon`` (> 0) added to ``var``, ``clip_obs``
    (> 0) the bound of a normalised entry; ``norm_obs`` False: unchanged."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    norm_obs: bool
    mean: list[float]
    var: list[float]
    epsilon: float = Field(gt=0)
    clip_obs: float = Field(gt=0)

    @field_validator("mean", "var", "epsilon", "clip_obs")
    @classmethod
    def _finite(cls, value: Any) -> Any:
        values = value if isinstance(value, list) else [value]
        if not all(math.isfinite(v) for v in values):
            raise ValueError("every number must be finite")
        return value

    @field_validator("mean", "var")
    @classmethod
    def _length(cls, value: list[float]) -> list[float]:
        if not any(
            len(value) >= size and (len(value) - size) % HISTORY_WIDTH == 0
            for size in OBSERVATION_SIZES
        ):
            raise ValueError(
                f"{len(value)} entries: the observation has {OBSERVATION_SIZES[0]}, "
                f"or {OBSERVATION_SIZES[1]} with the context features, plus {HISTORY_WIDTH} "
                "per step of history (history_steps)"
            )
        return value

    @field_validator("var")
    @classmethod
    def _variance(cls, value: list[float]) -> list[float]:
        if any(v < 0 for v in value):
            raise ValueError("a variance is ≥ 0")
        return value

    @model_validator(mode="after")
    def _same_length(self) -> ObsNormalizer:
        if len(self.mean) != len(self.var):
            raise ValueError(f"mean has {len(self.mean)} entries, var {len(self.var)}")
        return self

    @classmethod
    def of(cls, vecnormalize: Any) -> ObsNormalizer:
        """The observation statistics of an SB3 ``VecNormalize``."""
        return cls(
            norm_obs=bool(vecnormalize.norm_obs),
            mean=np.asarray(vecnormalize.obs_rms.mean, dtype=np.float64).tolist(),
            var=np.asarray(vecnormalize.obs_rms.var, dtype=np.float64).tolist(),
            epsilon=float(vecnormalize.epsilon),
            clip_obs=float(vecnormalize.clip_obs),
        )

    def normalize_obs(self, obs: np.ndarray) -> np.ndarray:
        """SB3's ``VecNormalize.normalize_obs``: (obs − mean) / √(var + ε), clipped to
        ±clip_obs, as float32 (elementwise: batch-independent)."""
        if not self.norm_obs:
            return np.array(obs, copy=True)
        mean, var = np.asarray(self.mean), np.asarray(self.var)
        scaled = (obs - mean) / np.sqrt(var + self.epsilon)
        return np.clip(scaled, -self.clip_obs, self.clip_obs).astype(np.float32)

    def save(self, file: Path) -> Path:
        """Write the statistics as JSON (floats round-trip exactly)."""
        write_text(file, json.dumps(self.model_dump(), indent=1) + "\n")  # through no link
        return file


def read_normalizer(file: Path) -> ObsNormalizer:
    """The statistics of a ``vecnormalize.json``; a bad file is a :class:`ControllerError`
    naming it and the key."""
    try:
        data = json.loads(file.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ControllerError(f"{file}: not JSON ({exc})") from None
    return validate_model(data, ObsNormalizer, str(file), ControllerError)


def unpickle_normalizer(file: Path) -> ObsNormalizer:
    """The statistics of a ``vecnormalize.pkl``: refused
    (:class:`~shipgym_baselines.errors.UnsafeFileError`) unless
    the command trusts pickles; an unreadable or foreign pickle is a clear error."""
    if not pickle_trusted():
        raise refuse_unpickling(
            file,
            f"a pickled VecNormalize (convert it to {NORMALIZER_FILE}: python -m "
            "shipgym_baselines.learned.normalizer FILE)",
        )
    from stable_baselines3.common.vec_env import VecNormalize

    try:
        with open(file, "rb") as fh:
            normalizer = pickle.load(fh)
    except (pickle.UnpicklingError, EOFError, AttributeError, ImportError, ValueError) as exc:
        raise ControllerError(f"{file}: not a readable VecNormalize file: {exc}") from exc
    if not isinstance(normalizer, VecNormalize):
        raise ControllerError(f"{file}: holds a {type(normalizer).__name__}, not a VecNormalize")
    return ObsNormalizer.of(normalizer)


def normalizer_file(folder: Path) -> Path | None:
    """The statistics file beside a model in ``folder``: its ``vecnormalize.json``, else
    its ``vecnormalize.pkl``, else None."""
    for name in (NORMALIZER_FILE, PICKLED_NORMALIZER_FILE):
        if (folder / name).is_file():
            return folder / name
    return None


def load_normalizer(file: Path) -> ObsNormalizer:
    """The statistics of a :func:`normalizer_file`: JSON as data, a pickle only when
    trusted (:func:`unpickle_normalizer`)."""
    if file.suffix == ".json":
        return read_normalizer(file)
    return unpickle_normalizer(file)


def main(argv: list[str] | None = None) -> int:
    """Convert each ``vecnormalize.pkl`` named into ``vecnormalize.json`` beside it."""
    from shipgym_baselines.learned.trust import trusting_pickle

    for name in sys.argv[1:] if argv is None else argv:
        file = Path(name)
        with trusting_pickle(True):  # the user names the files they trust
            normalizer = unpickle_normalizer(file)
        print(normalizer.save(file.with_name(NORMALIZER_FILE)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

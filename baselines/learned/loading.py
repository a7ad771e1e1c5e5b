"""A stable-baselines3 model zip read as data: nothing in it is unpickled.

SB3's ``Algorithm.load`` unpickles (cloudpickle) every non-JSON value of the zip's ``data``
entry — the policy class, the spaces, schedules, buffers — and so runs any code a hostile
zip puts there.  Scoring needs none of them.  :func:`load_data_only` rebuilds the model
from what is data:

* the policy class: the algorithm's ``MlpPolicy`` (``MlpLstmPolicy``; the env observes a
  flat Box), checked
  against the module the zip names (another class needs unpickling);
* ``policy_kwargs`` and ``use_sde`` from the JSON (kwargs holding pickled objects, e.g. a
  custom activation, need unpickling);
* the observation and action spaces from the env (:func:`shipgym.envs.core.observation_space`,
  :func:`~shipgym.envs.core.action_space`), checked against the bounds the zip records;
* the weights, ``policy.pth``, with ``torch.load(weights_only=True)``.

A zip that needs more is an :class:`~shipgym_baselines.errors.UnsafeFileError` naming
``--trust-pickle`` (:mod:`shipgym_baselines.learned.trust`).  The shipped agents act exactly as
through SB3's load (tests/golden/shipped_policy_actions.npz).
"""

from __future__ import annotations

import dataclasses
import io
import json
import pickle
import zipfile
import zlib
from pathlib import Path
from typing import Any

import numpy as np

from shipgym.envs.core import action_space, observation_space
from shipgym_baselines.errors import ControllerError
from shipgym_baselines.learned.trust import refuse_unpickling

#: where SB3 marks a value it pickled
PICKLED = ":serialized:"
#: the zip entry holding the policy weights
WEIGHTS_ENTRY = "policy.pth"
#: settings replaced on load: a scoring run neither learns nor stores transitions (the
#: entropy target of SAC / TQC only tunes training)
_INFERENCE = {
    "learning_rate": 0.0,
    "n_envs": 1,
    "n_steps": 1,
    "buffer_size": 1,
    "target_entropy": -1.0,
}


def is_pickled(value: Any) -> bool:
    """True if a JSON value of a zip's ``data`` holds a pickled object anywhere."""
    if isinstance(value, dict):
        return PICKLED in value or any(is_pickled(v) for v in value.values())
    if isinstance(value, list):
        return any(is_pickled(v) for v in value)
    return False


@dataclasses.dataclass(frozen=True)
class SavedModel:
    """What a model zip says about itself, read without torch: the algorithm that saved it
    (None when the zip does not tell) and the action mode its action space drives."""

    path: Path
    algo: str | None
    action_mode: str
    #: it observes the controller-context features too (trained with context_features)
    context_features: bool = False
    #: K: it observes the last K control steps too (trained with history_steps)
    history_steps: int = 0


def load_data_only(saved: SavedModel, algorithm: type) -> Any:
    """The SB3 model of the zip ``saved.path`` saved by ``algorithm`` (an SB3 / sb3-contrib
    class), built without unpickling, on the CPU, for the env's spaces in its action mode
    (the observation with the context features and history steps the model was trained
    with)."""
    import torch

    path = saved.path
    with zipfile.ZipFile(path) as archive:
        data = json.loads(archive.read("data").decode())
        weights = archive.read(WEIGHTS_ENTRY)
    alias = next(name for name in algorithm.policy_aliases if name.startswith("Mlp"))
    policy_class = algorithm.policy_aliases[alias]
    saved_class = data.get("policy_class")
    module = saved_class.get("__module__") if isinstance(saved_class, dict) else None
    if module != policy_class.__module__:
        raise refuse_unpickling(
            path,
            f"its policy class (module {module!r}) is not {algorithm.__name__}'s "
            f"{alias} ({policy_class.__module__}.{policy_class.__name__})",
        )
    kwargs = data.get("policy_kwargs", {})
    if not isinstance(kwargs, dict) or is_pickled(kwargs):
        raise refuse_unpickling(path, "its policy_kwargs hold pickled objects")
    kwargs = {k: v for k, v in kwargs.items() if k != "device"}
    obs_space = observation_space(saved.context_features, saved.history_steps)
    act_space = action_space(saved.action_mode)
    for key, space in (("observation_space", obs_space), ("action_space", act_space)):
        _check_bounds(path, key, data.get(key), space)
    model = algorithm(alias, env=None, device="cpu", _init_setup_model=False)
    model.observation_space, model.action_space = obs_space, act_space
    model.policy_kwargs = kwargs
    model.use_sde = bool(data.get("use_sde", False))
    for key, value in _INFERENCE.items():
        if key in vars(model) or key == "n_envs":
            setattr(model, key, value)
    try:
        model._setup_model()
        state = torch.load(io.BytesIO(weights), map_location="cpu", weights_only=True)
        model.policy.load_state_dict(state, strict=True)
    except pickle.UnpicklingError as exc:  # weights_only met something that is not a tensor
        raise refuse_unpickling(path, f"its {WEIGHTS_ENTRY} holds objects ({exc})") from None
    except (
        RuntimeError,
        TypeError,
        ValueError,
        KeyError,
        AttributeError,
        AssertionError,
        zlib.error,
    ) as exc:
        raise ControllerError(
            f"{path}: cannot rebuild its {algorithm.__name__} policy from the zip's JSON and "
            f"weights: {exc}"
        ) from None
    model.policy.set_training_mode(False)
    return model


def _check_bounds(path: Path, key: str, saved: Any, space: Any) -> None:
    """A :class:`ControllerError` unless the zip's recorded space ``key`` has the env's
    bounds (the printed ``low`` / ``high`` arrays of SB3's JSON; numpy elides an array of
    more than 1000 entries with ``...``: such a one must print as the env's does)."""
    for bound in ("low", "high"):
        text = saved.get(bound) if isinstance(saved, dict) else None
        want = getattr(space, bound)
        if isinstance(text, str) and "..." in text:
            if text == str(want):
                continue
            values = None
        else:
            try:
                values = np.array(str(text).strip("[]").split(), dtype=np.float64)
            except ValueError:
                values = None
        if values is None or not np.array_equal(values, want):
            raise ControllerError(
                f"{path}: its {key} has {bound} {text}; the env's is {want.tolist()}"
            )

"""One episode's result and its record: the metrics and trajectory of a (controller,
scenario, seed) episode as the evaluation loop gives it (:class:`EpisodeResult`, labelled
as :class:`EpisodeLabel` says), and the line of a run's ``episodes.jsonl`` that keeps it
(:func:`episode_record`, read back by :func:`read_episodes`).

``episodes.jsonl`` holds one JSON object per finished episode (scenario, controller, kind,
seed, training_seed and every metric); an episode's key is (scenario, controller, seed,
training_seed) and the file is read as a set keyed by it.  Strict JSON has no infinity or
NaN: a metric of ±inf (t_c = inf, "never converged") is the string ``"inf"`` / ``"-inf"``
and NaN is ``null`` (metrics ignore NaN), so a record reads back to the same numbers.  Read
back, each value is checked by type: a metric is a finite number, null, ``"inf"`` or
``"-inf"``; only :data:`BOOL_METRICS` are booleans and :data:`TEXT_METRICS` text; a
metric of :data:`NONNEGATIVE_METRICS` is never below 0, and none is beyond
:data:`~shipgym.limits.MAX_METRIC` in magnitude.

A controller's own figures of the episode (its ``episode_stats``) are the one mapping,
:data:`CONTROLLER_STATS`: they sit beside the benchmark's metrics and never replace one.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from shipgym.limits import MAX_CONTROLLER_STATS, MAX_METRIC, MAX_NAME_CHARS, MAX_STAT_TEXT_CHARS
from shipgym_baselines.errors import RunError
from shipgym_baselines.records.jsonfiles import from_plain, plain, short_json
from shipgym_baselines.records.outfiles import open_regular
from shipgym_baselines.records.trials import (
    TWIN_PLAYERS,
    deal_names,
    runs_of,
    shares_trials,
    twin_scenarios,
)

EPISODES_FILE = "episodes.jsonl"
#: the keys of an ``episodes.jsonl`` object that are not metrics
EPISODE_KEYS = ("scenario", "controller", "kind", "seed", "training_seed", "trajectory")

#: an episode's key: (scenario, controller, seed, training_seed)
Key = tuple[str, str, int, int | None]

#: the ``termination_reason`` of an episode its controller ended: ``reset`` or ``act``
#: raised, or gave an action that is malformed or not finite
#: (:class:`~shipgym_baselines.evaluation.ActGuard`)
CONTROLLER_ERROR = "controller_error"
#: ... or a call took longer than the limit (``--act-timeout``)
CONTROLLER_TIMEOUT = "controller_timeout"
#: the ``termination_reason`` values of an episode its controller ended
CONTROLLER_FAILURES = (CONTROLLER_ERROR, CONTROLLER_TIMEOUT)

#: the metric that holds a controller's own figures of its episode (its ``episode_stats``):
#: name → number, true / false, null or text (:func:`stats_problem`); no other metric is
#: the controller's to set
CONTROLLER_STATS = "controller_stats"
#: the metric saying why a controller's ``episode_stats`` were left out (it raised, ran over
#: the limit or gave no mapping of figures); the episode counts as the env ended it
STATS_ERROR = "stats_error"


@dataclasses.dataclass
class EpisodeResult:
    """Metrics and trajectory of one (controller, scenario, seed) episode; ``training_seed``:
    the seed a learned policy was trained with (None for the rest)."""

    controller: str
    kind: str
    scenario: str
    seed: int
    metrics: dict[str, Any]
    trajectory: dict[str, np.ndarray]
    training_seed: int | None = None

    def row(self) -> dict[str, Any]:
        return {
            "scenario": self.scenario,
            "controller": self.controller,
            "kind": self.kind,
            "seed": self.seed,
            **self.metrics,
        }


class EpisodeLabel(NamedTuple):
    """What the evaluation loop labels an episode's result with, as a run keys it: the
    scenario's table name (not its trial's), the controller's display name and the
    training seed of the policy that ran (None: the policy's own, as it reports it)."""

    scenario: str
    controller: str
    training_seed: int | None = None


def controller_failed(episode: Mapping[str, Any]) -> bool:
    """The episode (a record or a result's metrics) was ended by its controller's error or
    timeout (:data:`CONTROLLER_FAILURES`)."""
    return episode.get("termination_reason") in CONTROLLER_FAILURES


def episode_record(result: EpisodeResult) -> dict[str, Any]:
    """One ``episodes.jsonl`` object (trajectory aside)."""
    head = {
        "scenario": result.scenario,
        "controller": result.controller,
        "kind": result.kind,
        "seed": int(result.seed),
        "training_seed": result.training_seed,
    }
    return plain({**head, **result.metrics})


def episode_key(record: Mapping[str, Any]) -> Key:
    """(scenario, controller, seed, training_seed) of an episode record (or result row;
    training_seed None for a controller that is not trained)."""
    training_seed = record.get("training_seed")
    return (
        record["scenario"],
        record["controller"],
        int(record["seed"]),
        None if training_seed is None else int(training_seed),
    )


#: metrics whose value is text or null (every other metric is a number, null, "inf" or
#: "-inf"): ``error`` is the one-line message of an episode its controller ended
TEXT_METRICS = ("termination_reason", "error", STATS_ERROR)
#: metrics whose value is a boolean (true / false, or null)
BOOL_METRICS = ("success",)
#: metrics that are never negative: distances [m], angles' magnitudes [rad], times [s, ms],
#: step counts and the sums of costs (:func:`shipgym.metrics.compute_metrics`)
NONNEGATIVE_METRICS = (
    "ace",
    "ace_L",
    "t_c",
    "convergence_threshold",
    "mean_abs_cross_track",
    "std_abs_cross_track",
    "max_abs_cross_track",
    "mean_abs_heading_error",
    "std_abs_heading_error",
    "mean_abs_rudder",
    "std_abs_rudder",
    "rudder_travel",
    "rudder_command_travel",
    "J",
    "cost",
    "steps",
    "duration",
    "compute_ms",
    "compute_ms_max",
)


def stats_problem(stats: Any) -> str | None:
    """Why ``stats`` cannot be a controller's figures of an episode
    (:data:`CONTROLLER_STATS`), or None: a mapping of at most
    :data:`~shipgym.limits.MAX_CONTROLLER_STATS` names (text of at most
    :data:`~shipgym.limits.MAX_NAME_CHARS` characters), each to a number, true / false, null
    or text of at most :data:`~shipgym.limits.MAX_STAT_TEXT_CHARS` characters."""
    if not isinstance(stats, Mapping):
        return f"is a {type(stats).__name__}, not a mapping of names to numbers"
    if len(stats) > MAX_CONTROLLER_STATS:
        return f"has {len(stats)} entries, beyond the limit of {MAX_CONTROLLER_STATS}"
    for key, value in stats.items():
        if not isinstance(key, str) or not 0 < len(key) <= MAX_NAME_CHARS:
            return f"has the key {repr(key)[:40]}, not a name of 1 to {MAX_NAME_CHARS} characters"
        if value is None or isinstance(value, bool | int | float | np.bool_ | np.number):
            continue
        if isinstance(value, str) and len(value) <= MAX_STAT_TEXT_CHARS:
            continue
        return (
            f"gives {key!r} a {type(value).__name__}, not a number, true / false, null or "
            f"a text of at most {MAX_STAT_TEXT_CHARS} characters"
        )
    return None


class _Constant(ValueError):
    """A ``NaN`` / ``Infinity`` token: JSON's extension that strict JSON has not."""


def _no_constant(token: str) -> Any:
    raise _Constant(token)


def _metric_problem(key: str, value: Any) -> str | None:
    """Why ``value`` cannot be the metric ``key`` of an episode record, or None."""
    if key == CONTROLLER_STATS:
        problem = stats_problem(value)
        return None if problem is None else f"not a controller's figures: it {problem}"
    if key in TEXT_METRICS:
        return None if value is None or isinstance(value, str) else "not text"
    if key in BOOL_METRICS:
        return None if value is None or isinstance(value, bool) else "not true or false"
    if value == "-inf" and key in NONNEGATIVE_METRICS:
        return "negative, which this metric never is"
    if value is None or value in ("inf", "-inf"):
        return None
    if isinstance(value, bool):
        return f"not a number (only {', '.join(BOOL_METRICS)} is true or false)"
    if isinstance(value, int | float):
        try:
            finite = math.isfinite(value)
        except OverflowError:  # an integer beyond any float
            finite = False
        if not finite:
            return "not a finite number"
        return _range_problem(key, value)
    return "not a number"


def _range_problem(key: str, value: float) -> str | None:
    """Why the finite number ``value`` is no plausible metric ``key``, or None."""
    if abs(value) > MAX_METRIC:
        return f"beyond the limit of {MAX_METRIC:g} in magnitude"
    if value < 0 and key in NONNEGATIVE_METRICS:
        return "negative, which this metric never is"
    return None


def _bad_line(file: Path, number: int, problem: str) -> RunError:
    return RunError(f"{file}: line {number}: {problem}")


def _check_episode(record: Any, file: Path, number: int) -> dict[str, Any]:
    """``record`` (one parsed line) if it is an episode record; else a :class:`RunError`
    naming the file, the line and the problem."""
    if not isinstance(record, dict):
        raise _bad_line(file, number, f"not an episode record (a JSON {type(record).__name__})")
    absent = [k for k in EPISODE_KEYS[:5] if k not in record]
    if absent:
        raise _bad_line(file, number, f"not an episode record (no {', '.join(absent)})")
    for key in ("scenario", "controller", "kind"):
        if not isinstance(record[key], str):
            raise _bad_line(file, number, f"{key} {short_json(record[key])} is not text")
    for key in ("seed", "training_seed"):
        value = record[key]
        if not (isinstance(value, int) and not isinstance(value, bool)) and not (
            key == "training_seed" and value is None
        ):
            raise _bad_line(file, number, f"{key} {short_json(value)} is not an integer")
    for key, value in record.items():
        if key in EPISODE_KEYS:
            continue
        problem = _metric_problem(key, value)
        if problem is not None:
            raise _bad_line(file, number, f"metric {key} is {short_json(value)}, {problem}")
    return record


def _lines(file: Path) -> list[tuple[int, str]]:
    """The complete lines of ``file`` (numbered from 1), a last line cut short by a kill
    left out; a :class:`RunError` naming the line that is not UTF-8."""
    data = file.read_bytes()
    raw = data.split(b"\n")
    complete = raw[:-1]  # the part after the last newline: empty, or cut short by a kill
    lines = []
    for number, line in enumerate(complete, start=1):
        try:
            lines.append((number, line.decode("utf-8")))
        except UnicodeDecodeError:
            raise _bad_line(file, number, "not UTF-8 text") from None
    return lines


class _SuiteKeys(NamedTuple):
    """What a resolved suite (``run.json``'s) runs: scenarios and twins, the (scenario,
    controller) pairs that apply, each scenario's evaluation seeds, each controller's
    training seeds, the name each scenario's trials are dealt by."""

    scenarios: set[str]
    pairs: set[tuple[str, str]]
    seeds: dict[str, set[int]]  # scenario → its evaluation seeds
    trained: dict[str, list[int | None]]
    shared: bool  # each evaluation seed played by one training seed
    deal: dict[str, str]  # scenario → the name its trials are dealt by


def _suite_keys(suite: Mapping[str, Any]) -> _SuiteKeys:
    skip = {tuple(pair) for pair in suite["does_not_apply"]}
    trained = {c["name"]: list(c["training_seeds"]) for c in suite["controllers"]}
    twins = twin_scenarios(suite)
    players = set(suite.get(TWIN_PLAYERS, []))
    pairs = {(s, c) for s in suite["scenarios"] for c in trained}
    pairs |= {(t, c) for t in twins for c in trained if c in players}
    fewer = suite.get("scenario_seeds", {})
    everything = [*suite["scenarios"], *twins]
    seeds = {s: set(fewer.get(s, suite["seeds"])) for s in everything}
    return _SuiteKeys(
        set(everything), pairs - skip, seeds, trained, shares_trials(suite), deal_names(suite)
    )


def _foreign(key: Key, keys: _SuiteKeys) -> str | None:
    """Why the episode ``key`` is not one of a suite's (``keys``), or None when it is."""
    scenarios, pairs, seeds, trained, shared, deal = keys
    scenario, controller, seed, training_seed = key
    if controller not in trained:
        return f"controller {controller!r} is not in the run's suite"
    if scenario not in scenarios:
        return f"scenario {scenario!r} is not in the run's suite"
    if (scenario, controller) not in pairs:
        return f"{controller!r} does not apply to {scenario!r} in the run's suite"
    if seed not in seeds[scenario]:
        return f"seed {seed} is not one of the run's seeds of {scenario!r}"
    if training_seed not in trained[controller]:
        return f"training seed {training_seed} is not one of {controller!r}'s in the run"
    if shared and (training_seed, seed) not in runs_of(
        deal[scenario], sorted(seeds[scenario]), trained[controller], shared
    ):
        return (
            f"seed {seed} of {scenario!r} is dealt to another training seed of "
            f"{controller!r} than {training_seed} (the run shares the trials)"
        )
    return None


def read_episodes(
    folder: str | os.PathLike, suite: Mapping[str, Any] | None = None
) -> list[dict[str, Any]]:
    """The finished episodes of a run folder, numbers restored (±inf), as a set keyed by
    the episode key: a line repeating an earlier one is dropped; a last line cut short by
    a kill is left out.  A :class:`RunError` naming the file and line for a line that is
    not an episode record (not UTF-8, not JSON, a ``NaN`` / ``Infinity`` token, not an
    object, a key missing, a value of the wrong type: :func:`_metric_problem`), repeats a
    key with other content, or (given ``suite``, as ``run.json`` records it) holds an
    episode that is not the suite's.  An episode its controller ended
    (``controller_error`` / ``controller_timeout``) may be recorded again: the later line
    is the episode (``--retry-failed`` runs it again,
    :meth:`~shipgym_baselines.records.runlog.RunLog.retry`)."""
    file = Path(folder) / EPISODES_FILE
    if not file.is_file():
        return []
    keys = None if suite is None else _suite_keys(suite)
    records: dict[Key, dict[str, Any]] = {}
    first: dict[Key, int] = {}
    for number, line in _lines(file):
        try:
            parsed = json.loads(line, parse_constant=_no_constant)
        except _Constant as exc:
            strict = f'{exc} is not strict JSON (write null or "inf")'
            raise _bad_line(file, number, strict) from None
        except ValueError:
            raise _bad_line(file, number, "not JSON") from None
        record = _check_episode(parsed, file, number)
        key = episode_key(record)
        if keys is not None and (why := _foreign(key, keys)) is not None:
            raise _bad_line(file, number, why)
        record = {k: from_plain(v) for k, v in record.items()}
        if key in records and not controller_failed(records[key]):
            if _same(records[key], record):
                continue  # the same episode written twice: one episode
            raise _bad_line(
                file,
                number,
                f"episode {json.dumps(list(key))} again, with other values than on line "
                f"{first[key]}",
            )
        records[key], first[key] = record, number
    return list(records.values())


def _same(a: Mapping[str, Any], b: Mapping[str, Any]) -> bool:
    """Two records of one episode say the same, field by field (NaN equal to NaN)."""
    return _canonical(a) == _canonical(b)


def _canonical(record: Mapping[str, Any]) -> str:
    return json.dumps(plain(dict(record)), sort_keys=True)


def cut_partial_line(file: Path) -> None:
    """Cut a partial last line (a run killed while writing it) off ``file``."""
    if not file.is_file():
        return
    data = file.read_bytes()
    if data and not data.endswith(b"\n"):
        fd = open_regular(file, os.O_WRONLY)
        try:
            os.ftruncate(fd, data.rfind(b"\n") + 1)
        finally:
            os.close(fd)


__all__ = [
    "BOOL_METRICS",
    "CONTROLLER_ERROR",
    "CONTROLLER_FAILURES",
    "CONTROLLER_STATS",
    "CONTROLLER_TIMEOUT",
    "EPISODES_FILE",
    "EPISODE_KEYS",
    "NONNEGATIVE_METRICS",
    "STATS_ERROR",
    "TEXT_METRICS",
    "EpisodeLabel",
    "EpisodeResult",
    "Key",
    "controller_failed",
    "cut_partial_line",
    "episode_key",
    "episode_record",
    "read_episodes",
    "stats_problem",
]

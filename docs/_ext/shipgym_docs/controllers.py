"""One page per controller: the registry's built-ins and the shipped learned agents.

From the registration (:data:`shipgym_baselines.registry.CONTROLLERS`): kind, the action mode
(what it drives), the ships it applies to, its settings (the factory's keyword arguments, what
is used when one is not given: the paper's design, and the value the shipped chosen settings
give on each ship, ``configs/tuning/chosen/<name>.yaml``, with each study's validation
objective) and its docstring; a learned agent's page comes from its ``meta.json`` and its
chosen settings.
"""

from __future__ import annotations

import dataclasses
import inspect
import json
from pathlib import Path
from typing import Any

from shipgym.models import MODELS
from shipgym.scenarios.schema import GuidanceConfig
from shipgym_baselines.classical import lqr, nmpc, pid
from shipgym_baselines.classical.adaptive.settings import L1BacksteppingSettings
from shipgym_baselines.classical.l1_backstepping import L1Backstepping
from shipgym_baselines.learned.curves import agent_curves
from shipgym_baselines.learned.policy import POLICY_DIR, shipped_policies
from shipgym_baselines.plots.curves import plot_learning_curves
from shipgym_baselines.records.chosen import ALL_SHIPS, read_chosen
from shipgym_baselines.registry import CONTROLLERS, ControllerRecord
from shipgym_docs.pages import cell, rst_block, table, write_text

#: module -> the source paper(s) of its controllers (keys of docs/references.bib)
SOURCES = {
    "shipgym_baselines.classical.pid": "{cite:t}`xu2020vector`, {cite:t}`xu2021l1`",
    "shipgym_baselines.classical.lqr": "{cite:t}`borkowski2018adaptive`",
    "shipgym_baselines.classical.l1_backstepping": "{cite:t}`xu2021l1`",
    "shipgym_baselines.classical.nmpc": "{cite:t}`liu2019adaptive`",
    "shipgym_baselines.classical.oracle": (
        "a reference of this suite: NMPC on the true plant, generalised Gauss–Newton SQP "
        "{cite:p}`messerer2021survey`"
    ),
    "shipgym_baselines.classical.reference": "a reference of this suite (no paper)",
}

READS = {
    "rudder": (
        "`reset(context, seed)`: the nominal (pre-change) model, the path and the timing "
        "(`env.unwrapped.controller_context`, never the truth); `act(obs, info)`: the "
        "observation and `info` (measured heading and yaw rate, cross-track error, the "
        "period's fine-rate `samples`); returns the rudder action a ∈ [-1, 1]"
    ),
    "guidance": (
        "as a rudder controller, but returns the two guidance actions (length-scale factor "
        "2^a0, course offset a1·30°); the env's autopilot closes the heading loop"
    ),
}


def _code(value: object) -> str:
    return f"`{value!r}`"


def paper_values(factory: Any) -> dict[str, str]:
    """Keyword -> what the controller uses when it is neither given nor chosen (the paper's
    design, read from the controller's module), for the keywords whose signature default is
    None or that the factory takes through ``**kwargs``."""
    if not isinstance(factory, type):
        return {}
    if issubclass(factory, pid._GuidedPID):
        values = {k: _code(v) for k, v in pid.SETTINGS.items() if v is not None}
        values["preset"] = _code(factory.default_preset)
        values["tuning"] = _code(factory.default_tuning)
        values["natural_frequency_T"] = "none: `natural_frequency` [rad/s] is used"
        for key in pid.GUIDANCE_SETTINGS:
            default = GuidanceConfig.model_fields[key].default
            values[key] = f"the scenario's `guidance:` (default {_code(default)})"
        return values
    if issubclass(factory, lqr.LQR):
        return {
            "a0": "the paper's on mariner, else 1/T of the nominal Nomoto model",
            "c0": "the paper's on mariner, else K/T of the nominal Nomoto model",
            "lambda_y": f"{lqr.PAPER_LAMBDA_Y:g}·({lqr.PAPER_SHIP_LENGTH:g} m / L)² [1/m²]",
            "lambda_psi": _code(lqr.PAPER_LAMBDA_PSI),
            "lambda_delta": _code(lqr.PAPER_LAMBDA_DELTA),
            "drift_compensation": _code(False),
        }
    if issubclass(factory, nmpc.NMPC):
        values = {k: f"{_code(1.0)} (the ship's plan)" for k in _NMPC_FACTORS}
        values["settings"] = "the ship's plan (`ship_plan`; the paper's on nomoto2)"
        values["excitation_deg"] = _code(0.0)
        values["drift_compensation"] = _code(False)
        return values
    if issubclass(factory, L1Backstepping):
        values = {f.name: _code(f.default) for f in dataclasses.fields(L1BacksteppingSettings)}
        values["settings"] = "`L1BacksteppingSettings()` (the paper's)"
        return values
    return {}


#: the NMPC family's tuned factors (on the ship plan's horizon and weights)
_NMPC_FACTORS = ("horizon_scale", "cross_track_weight", "heading_weight", "rudder_weight")


def chosen_document(record: ControllerRecord) -> tuple[str, dict[str, Any]]:
    """(whose file, document) of the chosen settings ``record`` reads: its own, else (the
    NMPC members without a study) those of its ``tuning_name``."""
    own = read_chosen(record.name)
    fallback = getattr(record.factory, "tuning_name", None)
    if not own.get("ships") and fallback and fallback != record.name:
        return fallback, read_chosen(fallback)
    return record.name, own


def chosen_for(document: dict[str, Any], ship: str) -> dict[str, Any]:
    """The settings ``ship`` gets from ``document``: its section, else the ``all`` one."""
    ships = document.get("ships") or {}
    return dict(ships.get(ship, ships.get(ALL_SHIPS)) or {})


def _value(value: object) -> str:
    """A chosen value: a float to 6 significant digits, anything else as Python writes it."""
    if isinstance(value, float):
        return f"`{value:.6g}`"
    return _code(value)


def settings(record: ControllerRecord) -> list[tuple[str, ...]]:
    """Per keyword of the factory (and per chosen keyword it takes through ``**kwargs``):
    its default (a None default: what is used, :func:`paper_values`) and each ship's chosen
    value (``—``: none; the default is used)."""
    factory = record.factory
    target = factory.__init__ if isinstance(factory, type) else factory
    try:
        signature = inspect.signature(target)
    except (TypeError, ValueError):
        return []
    paper = paper_values(factory)
    _, document = chosen_document(record)
    ships = list(MODELS)
    chosen = {ship: chosen_for(document, ship) for ship in ships}
    keywords = [
        name
        for name, parameter in signature.parameters.items()
        if name != "self"
        and parameter.kind not in (parameter.VAR_POSITIONAL, parameter.VAR_KEYWORD)
    ]
    for ship in ships:
        keywords += [k for k in chosen[ship] if k not in keywords]
    rows = []
    for name in keywords:
        parameter = signature.parameters.get(name)
        if parameter is not None and parameter.default is parameter.empty:
            default = "required"
        elif parameter is not None and parameter.default is not None:
            default = _code(parameter.default)
        else:
            default = paper.get(name, "`None` (the description says what is used)")
        values = [_value(chosen[s][name]) if name in chosen[s] else "—" for s in ships]
        rows.append((f"`{name}`", default, *(values if document.get("ships") else ())))
    return rows


def studies(name: str, owner: str, document: dict[str, Any], learned: bool = False) -> str:
    """The provenance of the chosen settings ``name`` reads (``owner``'s ``document``): per
    ship its study, trials and validation objective (the tuned settings' and the paper
    default's), or a sentence that there are none."""
    if not document.get("ships"):
        return (
            "No chosen settings (`configs/tuning/chosen/"
            f"{name}.yaml` does not exist): every ship gets the defaults.\n"
        )
    rows = []
    for section, study in (document.get("studies") or {}).items():
        rows.append(
            (
                f"`{section}`",
                f"`{study.get('study', '')}`",
                study.get("trials", "—"),
                _objective(study.get("best_value")),
                _objective(study.get("default_value")),
                f"`{study['report']}`" if study.get("report") else "—",
            )
        )
    whose = (
        f"its own, `configs/tuning/chosen/{owner}.yaml`"
        if owner == name
        else f"`{owner}`'s, `configs/tuning/chosen/{owner}.yaml` (it has no study of its own)"
    )
    reader = (
        "`shipgym train --settings tuned` reads"
        if learned
        else 'the default construction (`preset="tuned"`) reads'
    )
    default = "the study's `default:` settings" if learned else "the paper's design"
    return (
        f"The chosen settings {reader} are {whose}, written by `shipgym tune` "
        "([Tuning](../../tuning.md)).  The validation objective is the geometric mean over "
        "the study's validation trials of the cost ratio C / C_oracle (lower is better): "
        f"with the chosen settings and with {default} (default).\n\n"
        + table(
            ["ship", "study", "trials", "objective: chosen", "objective: default", "report"],
            rows,
        )
    )


def _objective(value: object) -> str:
    return f"{float(value):.3f}" if isinstance(value, int | float) else "—"


def _ships(record: ControllerRecord) -> str:
    ships = record.applies_to if record.applies_to is not None else tuple(MODELS)
    return ", ".join(f"`{s}`" for s in ships)


def page(record: ControllerRecord) -> str:
    factory = record.factory
    module = factory.__module__
    rows = [
        ("kind", record.kind),
        ("action mode", f"`{record.action_mode}`"),
        ("reads", READS[record.action_mode]),
        ("applies to", _ships(record)),
        ("source", SOURCES.get(module, "—")),
        ("defined in", f"`{module}.{factory.__qualname__}`"),
    ]
    if record.name in ("oracle", "oracle_frozen"):
        rows[2] = ("reads", READS["rudder"] + "; and the plant's truth (privileged channel)")
    parts = [
        f"# {record.name}\n",
        table(["", ""], rows),
        "\n## Settings\n",
        _settings_section(record),
        "\nA suite passes them in its long form: "
        f"`{{controller: {record.name}, name: DISPLAY_NAME, settings: {{keyword: value}}}}`.\n",
        "\n## Description\n",
        rst_block(inspect.getdoc(factory) or ""),
    ]
    return "\n".join(parts)


def _settings_section(record: ControllerRecord) -> str:
    rows = settings(record)
    if not rows:
        return "No settings.\n"
    owner, document = chosen_document(record)
    if not document.get("ships"):
        return table(["keyword", "default"], rows) + "\n" + studies(record.name, owner, document)
    header = ["keyword", "default", *(f"chosen: {ship}" for ship in MODELS)]
    return (
        "The default is what is used when the keyword is not given and no chosen setting "
        "applies; a `chosen: SHIP` column is the shipped tuned value on that ship (`—`: none, "
        "the default is used).  A keyword given explicitly wins over both.\n\n"
        + table(header, rows)
        + "\n"
        + studies(record.name, owner, document)
    )


def seed_rows(metas: list[Path]) -> list[tuple[Any, ...]]:
    """Per training seed: env steps, teacher labels, wall time, the best validation cost
    ratio of its learning curve and where the run stopped (from the shipped files)."""
    rows = []
    for file in metas:
        meta = json.loads(file.read_text())
        curve_file = file.with_name("learning_curve.json")
        curve = json.loads(curve_file.read_text()) if curve_file.is_file() else {}
        scores = curve.get("selection") or []
        best = min(range(len(scores)), key=scores.__getitem__) if scores else None
        at = "–" if best is None else f"{curve['env_steps'][best]:,}"
        rows.append(
            (
                file.parent.name,
                f"{meta.get('env_steps', 0):,}",
                f"{meta.get('teacher_labels', 0):,}" if "teacher_labels" in meta else "–",
                f"{meta.get('wall_time_s', 0.0):.0f}",
                "–" if best is None else f"{scores[best]:.2f}",
                at,
                f"{len(scores)}",
            )
        )
    return rows


#: the oracle's student and its two arms, drawn side by side on the learned-agents page
STUDENTS = ("dagger", "bc", "ppo_history")

SEED_HEADER = [
    "training seed",
    "env steps",
    "teacher labels",
    "wall time [s]",
    "best validation cost ratio",
    "at env step",
    "validations",
]


def learned_page(name: str) -> str:
    folder = POLICY_DIR / name
    metas = sorted(folder.glob("seed_*/meta.json")) or sorted(folder.glob("meta.json"))
    meta = json.loads(metas[0].read_text())
    config = meta.get("config", {})
    trainer = meta.get("trainer")
    rows = [
        ("kind", "learned"),
        ("algorithm", f"`{meta.get('algo')}` (stable-baselines3 / sb3-contrib)"),
        *([("trained by", f"`{trainer}` (a student of the `oracle`)")] if trainer else []),
        ("history window", f"{meta.get('history_steps', 0)} control steps"),
        ("action mode", f"`{meta.get('action_mode')}`"),
        ("reads", "the observation only (deterministic policy)"),
        ("applies to", ", ".join(f"`{s}`" for s in MODELS)),
        ("training seeds", ", ".join(p.parent.name for p in metas)),
        ("trained on", f"distribution `{config.get('env', {}).get('distribution')}`"),
        ("env steps (seed 0)", meta.get("env_steps")),
        ("config", f"`configs/agents/{name}.yaml`"),
    ]
    hyper = config.get("hyperparams", {})
    document = read_chosen(name)
    chosen = chosen_for(document, ALL_SHIPS)
    curves = curves_section(name)
    tuned = (
        [
            "\n## Chosen settings\n",
            table(["setting", "chosen"], [(f"`{k}`", _value(v)) for k, v in chosen.items()]),
            "\n" + studies(name, name, document, learned=True),
        ]
        if chosen
        else []
    )
    return "\n".join(
        [
            f"# {name}\n",
            f"A shipped learned agent (`shipgym_baselines/learned/policies/{name}`).\n",
            table(["", ""], rows),
            "\n## Hyperparameters\n",
            table(["name", "value"], [(f"`{k}`", cell(v)) for k, v in hyper.items()]),
            "\n## Policy\n",
            f"`{config.get('policy')}`, `policy_kwargs` = `{config.get('policy_kwargs')}`\n",
            "\n## Training seeds\n",
            "Each seed's run, from its shipped `meta.json` and `learning_curve.json` (the "
            "validation cost ratio: the geometric mean over the validation trials of the "
            "cost over the oracle's; the shipped model is the best one).\n",
            table(SEED_HEADER, seed_rows(metas)),
            *curves,
            *tuned,
        ]
    )


def curves_section(name: str) -> list[str]:
    """The learning-curve section of a learned agent's page ([] when it ships no curve)."""
    if not agent_curves(name):
        return []
    return [
        "\n## Learning curves\n",
        "Each seed's validation evaluations over its training (`learning_curve.json`): "
        "the validation cost ratio on a log axis where the run selects on it, the oracle "
        "= 1 dashed (the gap to the oracle is the height above the line), each seed's "
        "shipped model ringed; else the validation mean return.  The scores are the ones "
        "recorded while the seed trained, against the oracle and validation trials of that "
        "time (`config.eval.n_episodes` in its `meta.json`): curves of agents trained under "
        "another oracle revision or on fewer trials do not compare.\n",
        f"![learning curves of {name}](img/{name}_curves.png)\n",
    ]


def index(names: list[str], learned: list[str]) -> str:
    rows = [
        (f"[{n}]({n}.md)", CONTROLLERS[n].kind, CONTROLLERS[n].action_mode, _ships(CONTROLLERS[n]))
        for n in names
    ]
    rows += [
        (f"[{n}]({n}.md)", "learned", "", ", ".join(f"`{s}`" for s in MODELS)) for n in learned
    ]
    return (
        "# Controllers\n\n"
        "Every registered controller (`shipgym_baselines.registry`) and every shipped learned "
        "agent, generated from the registry and the agents' `meta.json`.\n\n"
        + table(["controller", "kind", "action mode", "applies to"], rows)
        + "\n```{toctree}\n:hidden:\n:glob:\n\n*\n```\n"
    )


def write(root: Path) -> list[Path]:
    folder = root / "controllers"
    names = list(CONTROLLERS)
    learned = [n for n in shipped_policies() if n not in CONTROLLERS]
    out = [write_text(folder / "index.md", index(names, learned))]
    out += [write_text(folder / f"{n}.md", page(CONTROLLERS[n])) for n in names]
    out += [write_text(folder / f"{n}.md", learned_page(n)) for n in learned]
    for n in learned:
        out += plot_learning_curves(folder / "img", {n: agent_curves(n)}, stem=f"{n}_curves")
    students = {n: agent_curves(n) for n in STUDENTS if n in learned}
    out += plot_learning_curves(folder / "img", students, stem="students_curves")
    return out

"""One page per controller: the registry's built-ins and the shipped learned agents.

From the registration (:data:`shipgym_baselines.registry.CONTROLLERS`): kind, the action mode
(what it drives), the ships it applies to, its settings (the factory's keyword arguments with
their defaults) and its docstring; a learned agent's page comes from its ``meta.json``.
"""

from __future__ import annotations

import inspect
import json
from pathlib import Path

from shipgym.models import MODELS
from shipgym_baselines.learned.policy import POLICY_DIR, shipped_policies
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


def settings(record: ControllerRecord) -> list[tuple[str, str]]:
    """The factory's keyword arguments and their defaults."""
    factory = record.factory
    target = factory.__init__ if isinstance(factory, type) else factory
    try:
        signature = inspect.signature(target)
    except (TypeError, ValueError):
        return []
    rows = []
    for name, parameter in signature.parameters.items():
        if name == "self" or parameter.kind in (parameter.VAR_POSITIONAL, parameter.VAR_KEYWORD):
            continue
        default = "required" if parameter.default is parameter.empty else repr(parameter.default)
        rows.append((f"`{name}`", f"`{default}`"))
    return rows


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
    if record.name == "oracle":
        rows[2] = ("reads", READS["rudder"] + "; and the plant's truth (privileged channel)")
    parts = [
        f"# {record.name}\n",
        table(["", ""], rows),
        "\n## Settings\n",
        (table(["keyword", "default"], settings(record)) if settings(record) else "No settings.\n"),
        "\nA suite passes them in its long form: "
        f"`{{controller: {record.name}, name: DISPLAY_NAME, settings: {{keyword: value}}}}`.\n",
        "\n## Description\n",
        rst_block(inspect.getdoc(factory) or ""),
    ]
    return "\n".join(parts)


def learned_page(name: str) -> str:
    folder = POLICY_DIR / name
    metas = sorted(folder.glob("seed_*/meta.json")) or sorted(folder.glob("meta.json"))
    meta = json.loads(metas[0].read_text())
    config = meta.get("config", {})
    rows = [
        ("kind", "learned"),
        ("algorithm", f"`{meta.get('algo')}` (stable-baselines3 / sb3-contrib)"),
        ("action mode", f"`{meta.get('action_mode')}`"),
        ("reads", "the observation only (deterministic policy)"),
        ("applies to", ", ".join(f"`{s}`" for s in MODELS)),
        ("training seeds", ", ".join(p.parent.name for p in metas)),
        ("trained on", f"distribution `{config.get('env', {}).get('distribution')}`"),
        ("env steps (seed 0)", meta.get("env_steps")),
        ("config", f"`configs/agents/{name}.yaml`"),
    ]
    hyper = config.get("hyperparams", {})
    return "\n".join(
        [
            f"# {name}\n",
            f"A shipped learned agent (`shipgym_baselines/learned/policies/{name}`).\n",
            table(["", ""], rows),
            "\n## Hyperparameters\n",
            table(["name", "value"], [(f"`{k}`", cell(v)) for k, v in hyper.items()]),
            "\n## Policy\n",
            f"`{config.get('policy')}`, `policy_kwargs` = `{config.get('policy_kwargs')}`\n",
        ]
    )


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
    return out

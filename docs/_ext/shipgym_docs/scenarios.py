"""The scenario catalogue (``configs/scenarios``): one page per scenario and a route figure.

Each page says what changes, when and by how much (the ``events``), the scenario's size
(route length, ship lengths, time limit, control steps), its source and the reasons for its
sizes (the YAML's ``description``, ``source`` and comments), the suites that use it, and the
YAML itself.
"""

from __future__ import annotations

import io
import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import yaml

from shipgym.config import catalogue, list_names
from shipgym.scenarios.families import FAMILIES
from shipgym.scenarios.loader import Scenario, list_scenarios, load_scenario
from shipgym_docs.pages import cell, table, write_bytes, write_text


def yaml_text(name: str) -> str:
    """The catalogue file of scenario ``name``, as shipped."""
    return catalogue("scenarios").joinpath(f"{name}.yaml").read_text(encoding="utf-8")


def comments(text: str) -> list[str]:
    """The YAML's comments as paragraphs: wrapped comment lines joined; a paragraph ends at a
    line ending with a full stop or at a line that is not a comment."""
    paragraphs: list[str] = []
    current: list[str] = []
    for line in (raw.strip() for raw in text.splitlines()):
        if line.startswith("#"):
            current.append(line.lstrip("#").strip())
            if not current[-1].endswith("."):
                continue
        if current:
            paragraphs.append(" ".join(current))
            current = []
    if current:
        paragraphs.append(" ".join(current))
    return [p for p in paragraphs if p]


def suites_using() -> dict[str, list[str]]:
    """Scenario name -> the suites (``configs/suites``) that list it."""
    out: dict[str, list[str]] = {}
    for suite in list_names("suites"):
        data = yaml.safe_load(catalogue("suites").joinpath(f"{suite}.yaml").read_text())
        for name in data.get("scenarios") or []:
            out.setdefault(str(name), []).append(suite)
    return out


def changes(sc: Scenario) -> str:
    """What changes and when, one line per event (or "nothing")."""
    parts = []
    for event in sc.config.events:
        params = ", ".join(f"{k} → {v:g}" for k, v in event.params.items())
        how = f"ramp over {event.duration:g} s" if event.kind == "ramp" else "step"
        parts.append(f"t = {event.time:g} s ({how}): {params}")
    current = sc.config.disturbances.model_dump(exclude_defaults=True)
    if current:
        parts.append(f"disturbances: `{current}`")
    return "; ".join(parts) or "nothing (a nominal run)"


def route_png(sc: Scenario) -> bytes:
    """A small PNG of the route: the path, its waypoints, the start."""
    path = sc.path
    s = np.linspace(0.0, path.length, 400)
    xy = np.asarray(path.point(s))
    wp = np.asarray(sc.config.path.waypoints)
    x0 = sc.initial_state()
    fig, ax = plt.subplots(figsize=(4.0, 3.0), dpi=80)
    # north-east axes: x north (up), y east (right)
    ax.plot(xy[:, 1], xy[:, 0], "-", color="C0", lw=1.5, label="path")
    ax.plot(wp[:, 1], wp[:, 0], "o", color="C0", ms=3)
    ax.plot(
        [x0[sc.model.state_index("y")]],
        [x0[sc.model.state_index("x")]],
        "^",
        color="C3",
        label="start",
    )
    ax.set_xlabel("east y [m]")
    ax.set_ylabel("north x [m]")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_title(sc.name, fontsize=9)
    ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", metadata={"Software": None})
    plt.close(fig)
    return buffer.getvalue()


def size(sc: Scenario) -> tuple[str, str, str]:
    """Route length (m and ship lengths), time limit (s and control steps)."""
    steps = math.ceil(sc.config.time_limit / sc.control_period - 1e-9)
    route = f"{sc.path.length:.4g} m ({sc.path.length / sc.ship_length:.3g} L)"
    return route, f"{sc.config.time_limit:g} s", str(steps)


def page(name: str, used: list[str]) -> str:
    sc = load_scenario(name)
    text = yaml_text(name)
    route, limit, steps = size(sc)
    rows = [
        ("ship", f"{{ref}}`{sc.model.name} <ship-{sc.model.name}>`"),
        ("change family", f"`{sc.family}`: {FAMILIES[sc.family].changes}"),
        ("what changes, when", changes(sc)),
        ("path", f"{sc.config.path.type}, {len(sc.config.path.waypoints)} waypoints"),
        ("route length", route),
        ("time limit", f"{limit} ({steps} control steps of {sc.control_period:g} s)"),
        ("source", sc.config.source or "—"),
        ("suites", ", ".join(f"`{s}`" for s in used) or "none (catalogue only)"),
    ]
    notes = comments(text)
    return "\n".join(
        [
            f"# {name}\n",
            (sc.config.description or "").strip() + "\n",
            f"![route of {name}](img/{name}.png)\n",
            table(["", ""], rows),
            "\n## Why these sizes\n",
            ("\n".join(f"- {cell(n)}" for n in notes) if notes else "No comments in the file.")
            + "\n",
            f"\n## `configs/scenarios/{name}.yaml`\n",
            "```yaml\n" + text.rstrip() + "\n```\n",
            f"\nRun it: `shipgym run {name} pid_los`, or "
            f'`gym.make("ShipPathFollow-v0", scenario={name!r})`.\n',
        ]
    )


def index(names: list[str], used: dict[str, list[str]]) -> str:
    rows = []
    for name in names:
        sc = load_scenario(name)
        route, limit, _ = size(sc)
        rows.append((f"[{name}]({name}.md)", sc.model.name, changes(sc), route, limit))
    return (
        "# Scenario catalogue\n\n"
        "Every scenario in `configs/scenarios/` (`shipgym scenarios`), generated from its YAML: "
        "what changes and when, its size, its source and why. The held-out test scenarios "
        "(`heldout:N`) are drawn from `configs/distributions/heldout.yaml`.\n\n"
        + table(["scenario", "ship", "what changes, when", "route", "time limit"], rows)
        + "\n```{toctree}\n:hidden:\n:glob:\n\n*\n```\n"
    )


def write(root: Path) -> list[Path]:
    folder = root / "scenarios"
    names = list_scenarios()
    used = suites_using()
    out = [write_text(folder / "index.md", index(names, used))]
    for name in names:
        out.append(write_text(folder / f"{name}.md", page(name, used.get(name, []))))
        out.append(write_bytes(folder / "img" / f"{name}.png", route_png(load_scenario(name))))
    return out

"""One page per registered ``ShipPathFollow*`` env id, from the env class's docstring.

The docstring (:class:`shipgym.envs.path_follow.ShipPathFollowEnv`,
:class:`shipgym.envs.randomized.ShipPathFollowRandomizedEnv`) is the single source of the
contract; the page adds the id's own numbers, read from its default scenario.
"""

from __future__ import annotations

import importlib
import inspect
import math
from pathlib import Path

import gymnasium as gym

import shipgym
from shipgym.envs import core
from shipgym.scenarios.loader import load_scenario
from shipgym_docs.pages import rst_block, table, write_text

PREFIX = "ShipPathFollow"


def env_ids() -> list[str]:
    """The registered env ids starting ``ShipPathFollow`` (``import shipgym`` registers them)."""
    return sorted(i for i in gym.registry if i.startswith(PREFIX))


def _entry(spec: gym.envs.registration.EnvSpec) -> type:
    module, attr = str(spec.entry_point).split(":")
    return getattr(importlib.import_module(module), attr)


def _versions(env_id: str) -> str:
    """The other versions of the same name, linked."""
    stem = env_id.rsplit("-v", 1)[0]
    others = [i for i in env_ids() if i.rsplit("-v", 1)[0] == stem and i != env_id]
    return ", ".join(f"[{i}]({i}.md)" for i in others) or "none"


def _scenario_rows(name: str) -> list[tuple[str, str]]:
    sc = load_scenario(name)
    model = sc.model
    steps = math.ceil(sc.config.time_limit / sc.control_period - 1e-9)
    rows = [
        ("ship", f"{{ref}}`{model.name} <ship-{model.name}>`"),
        ("default scenario", f"[`{name}`](../scenarios/{name}.md)"),
        ("control period Ts", f"{sc.control_period:g} s"),
        ("fine step h (RK4)", f"{sc.fine_step:g} s ({sc.substeps} substeps)"),
        ("rudder limit δmax", f"{math.degrees(model.rudder_limit):g}°"),
        ("ship length L", f"{sc.ship_length:g} m"),
        ("nominal speed U0", f"{model.nominal_speed:.4g} m/s"),
        ("corridor half-width e_max", f"{sc.max_cross_track:g} m"),
        ("yaw-rate scale 2U0/L", f"{2 * model.nominal_speed / sc.ship_length:.4g} rad/s"),
        ("time limit", f"{sc.config.time_limit:g} s ({steps} steps)"),
    ]
    for mode in core.ACTION_MODES:
        rows.append((f"action space (`{mode}`)", f"`{core.action_space(mode)}`"))
    rows.append(("observation space", f"`{core.observation_space()}`"))
    return rows


def page(env_id: str) -> str:
    """The page of one env id."""
    spec = gym.spec(env_id)
    cls = _entry(spec)
    rows: list[tuple[str, str]] = [
        ("entry point", f"`{spec.entry_point}`"),
        ("vector entry point", f"`{spec.vector_entry_point}`"),
        ("`gym.make` defaults", f"`{spec.kwargs}`"),
        ("`max_episode_steps`", f"{spec.max_episode_steps}"),
        ("other versions", _versions(env_id)),
    ]
    if "scenario" in spec.kwargs:
        rows += _scenario_rows(spec.kwargs["scenario"])
    else:
        dist = spec.kwargs.get("distribution")
        rows.append(("scenario distribution", f"`configs/distributions/{dist}.yaml`"))
    text = [
        f"# {env_id}\n",
        f"```python\nimport gymnasium as gym\nimport shipgym\n\nenv = gym.make({env_id!r})\n```\n",
        table(["", ""], rows),
        f"\n## The contract (`{cls.__module__}.{cls.__name__}`)\n",
        rst_block(inspect.getdoc(cls) or ""),
    ]
    return "\n".join(text)


def index() -> str:
    rows = []
    for env_id in env_ids():
        kwargs = gym.spec(env_id).kwargs
        default = kwargs.get("scenario") or f"distribution `{kwargs.get('distribution')}`"
        rows.append((f"[{env_id}]({env_id}.md)", default))
    return (
        "# Environments\n\n"
        f"Every env id that `import shipgym` registers (shipgym {shipgym.__version__}), "
        "generated from the env's docstring.\n\n"
        + table(["env id", "default scenario"], rows)
        + "\n```{toctree}\n:hidden:\n:glob:\n\n*\n```\n"
    )


def write(root: Path) -> list[Path]:
    folder = root / "envs"
    out = [write_text(folder / "index.md", index())]
    out += [write_text(folder / f"{env_id}.md", page(env_id)) for env_id in env_ids()]
    return out

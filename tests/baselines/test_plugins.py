"""Anyone's controller enters the benchmark (docs/plugins.md, "Enter your controller"):
specs ``module:Attr`` / ``file.py:Attr``, installed entry points, a suite's long form, in
worker processes too, and the "Enter your controller" example of docs/plugins.md as written."""

from __future__ import annotations

import multiprocessing
import re
import shlex
import sys
import textwrap
import tomllib
from collections.abc import Iterator
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from shipgym.config import ConfigError
from shipgym.envs.context import ControllerContext
from shipgym_baselines.cli import main
from shipgym_baselines.errors import ControllerError, RunError
from shipgym_baselines.evaluation import EVAL_SEED_OFFSET, evaluate, run_episode
from shipgym_baselines.leaderboard.jobs import check_controllers, run_job
from shipgym_baselines.leaderboard.run import run_leaderboard
from shipgym_baselines.plugins import ControllerEntry, anchored, entry_point_names, parse_spec
from shipgym_baselines.registry import (
    CONTROLLERS,
    applies_to,
    controller_kind,
    controller_label,
    make_controller,
    unknown_controller,
)
from shipgym_baselines.suite import load_suite

#: the docs page of plug-ins, whose example blocks run as written
PLUGINS_PAGE = Path(__file__).resolve().parents[2] / "docs" / "plugins.md"

#: a user's controller file: a Policy class, a factory function, a Policy instance
POLICY_FILE = """
import numpy as np


class Steer:
    name = "steer"
    kind = "classical"

    def __init__(self, gain: float = 2.0) -> None:
        self.gain = gain

    def reset(self, context, seed=None):
        pass

    def act(self, obs, info):
        rudder = -self.gain * (obs[0] + obs[1]) - 4.0 * obs[3]
        return np.clip(np.array([rudder], dtype=np.float32), -1.0, 1.0)


class Unnamed(Steer):
    name = None  # no name of its own: the spec's attribute names it


def make_soft():
    return Steer(gain=1.0)


instance = Steer(gain=3.0)
instance.name = "steer_instance"
"""


@pytest.fixture
def policy_file(tmp_path: Path) -> Path:
    file = tmp_path / "user" / "steer.py"
    file.parent.mkdir()
    file.write_text(POLICY_FILE)
    return file


@pytest.fixture
def forget_modules() -> Iterator[list[str]]:
    """Names of modules a test imports from its tmp folder: removed from sys.modules after."""
    names: list[str] = []
    yield names
    for name in [*names, *(m for m in sys.modules if m.startswith("shipgym_plugin_"))]:
        sys.modules.pop(name, None)


def _tiny_suite(folder: Path, controllers: list[Any], **extra: Any) -> Path:
    suite = folder / "suite.yaml"
    body = {"name": "tiny", "scenarios": ["nominal"], "controllers": controllers, "seeds": 1}
    suite.write_text(yaml.safe_dump({**body, **extra}, sort_keys=False))
    return suite


# ------------------------------------------------------------------ specs


def test_spec_forms_are_parsed() -> None:
    assert str(parse_spec("my.module:MyPolicy")) == "my.module:MyPolicy"
    assert parse_spec("path/to/file.py:Outer.Inner").is_file
    assert parse_spec("C:\\agents\\file.py:MyPolicy").target == "C:\\agents\\file.py"
    for not_a_spec in ("pid_los", "heldout:3", "results/agents/ppo", "model.zip", "a/b.txt:X"):
        assert parse_spec(not_a_spec) is None, not_a_spec


@pytest.mark.parametrize(
    ("attr", "label", "gain"),
    [("Steer", "steer", 2.0), ("make_soft", "make_soft", 1.0), ("instance", "steer_instance", 3.0)],
)
def test_a_file_spec_names_a_class_a_factory_or_an_instance(
    policy_file: Path, attr: str, label: str, gain: float, forget_modules: list[str]
) -> None:
    spec = f"{policy_file}:{attr}"
    policy, mode = make_controller(spec)
    assert (policy.name, policy.kind, mode, policy.gain) == (label, "classical", "rudder", gain)
    (result,) = evaluate(spec, "nominal", [0])
    assert (result.controller, result.kind) == (label, "classical")
    assert result.metrics["termination_reason"] in {"goal", "time_limit"}
    assert controller_label(spec) == label and controller_kind(label) == "classical"


def test_a_file_is_loaded_once_per_process(policy_file: Path, forget_modules: list[str]) -> None:
    first, _ = make_controller(f"{policy_file}:Steer")
    second, _ = make_controller(f"{policy_file}:Steer")
    assert type(first) is type(second)  # one module object, not a fresh class per episode
    assert first is not second  # but a fresh policy per episode


def test_an_attribute_without_a_name_is_named_by_the_spec(
    policy_file: Path, forget_modules: list[str]
) -> None:
    assert controller_label(f"{policy_file}:Unnamed") == "Unnamed"


def test_a_module_spec_is_found_in_the_working_directory(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, forget_modules: list[str]
) -> None:
    """The console script's sys.path does not hold the working directory: found anyway."""
    (tmp_path / "steer_module_cwd.py").write_text(POLICY_FILE)
    forget_modules.append("steer_module_cwd")
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, "path", [p for p in sys.path if p not in ("", str(tmp_path))])
    policy, _ = make_controller("steer_module_cwd:Steer")
    assert policy.name == "steer" and type(policy).__module__ == "steer_module_cwd"


def test_bad_specs_are_clear_errors(policy_file: Path, forget_modules: list[str]) -> None:
    cases = {
        f"{policy_file}:Nope": r"has no attribute 'Nope' \(it has: .*Steer.*make_soft",
        f"{policy_file.parent}/missing.py:Steer": "controller file not found: .*missing.py",
        "no_such_module_xyz:Steer": "module 'no_such_module_xyz' not found",
        f"{policy_file}:np": "is a module, not a Policy class, a factory function or a Policy",
        f"{policy_file.parent}/no_such_agent": "no such file or folder",
        str(policy_file): r"is a Python file: name the Policy in it, .*steer\.py:ClassName",
    }
    for spec, message in cases.items():
        with pytest.raises(ControllerError, match=message):
            make_controller(spec)


def test_a_user_modules_own_error_keeps_its_traceback(tmp_path: Path) -> None:
    broken = tmp_path / "broken.py"
    broken.write_text("x = 1 / 0\n")
    with pytest.raises(ZeroDivisionError):
        make_controller(f"{broken}:x")


def test_a_module_that_exits_while_it_is_loaded_is_a_clear_error(tmp_path: Path) -> None:
    """``sys.exit`` in a plug-in's module is one line naming the spec, not a silent exit."""
    leaves = tmp_path / "leaves.py"
    leaves.write_text("import sys\nsys.exit(3)\n")
    with pytest.raises(ControllerError) as refused:
        make_controller(f"{leaves}:P")
    assert str(refused.value) == (
        f"controller '{leaves}:P': its module exits while it is loaded (SystemExit: 3)"
    )


@pytest.mark.parametrize(
    ("body", "message"),
    [
        ("class P:\n    name = 'p'\n", r"class P is not a Policy \(it needs reset"),
        (
            "from steer import Steer\nclass P(Steer):\n    action_mode = 'thrust'\n",
            "action_mode must be one of",
        ),
        (
            "from steer import Steer\nclass P(Steer):\n    applies_to = ['titanic']\n",
            r"unknown ship\(s\) \['titanic'\]",
        ),
        ("from steer import Steer\nclass P(Steer):\n    kind = 'magic'\n", "kind must be one of"),
        ("from steer import Steer\nclass P(Steer):\n    name = 'pid_los'\n", "registered"),
    ],
)
def test_bad_plugin_traits_are_clear_errors(
    policy_file: Path,
    body: str,
    message: str,
    monkeypatch: pytest.MonkeyPatch,
    forget_modules: list[str],
) -> None:
    monkeypatch.syspath_prepend(str(policy_file.parent))
    forget_modules.append("steer")
    plugin = policy_file.parent / "plugin.py"
    plugin.write_text(body)
    with pytest.raises(ControllerError, match=message):
        make_controller(f"{plugin}:P")


def test_traits_of_a_plugin_reach_the_table(
    tmp_path: Path, scratch_registry: None, forget_modules: list[str]
) -> None:
    """A guidance-mode plug-in for one ship: its mode reaches the env, its ships the rows."""
    file = tmp_path / "guide.py"
    file.write_text(
        textwrap.dedent(
            """
            import numpy as np

            class Guide:
                name = "guide"
                kind = "classical"
                action_mode = "guidance"
                applies_to = ("mariner",)

                def reset(self, context, seed=None):
                    pass

                def act(self, obs, info):
                    return np.zeros(2, dtype=np.float32)  # the env's own guidance law
            """
        )
    )
    policy, mode = make_controller(f"{file}:Guide")
    assert mode == policy.action_mode == "guidance"
    assert applies_to("guide", "mariner") and not applies_to("guide", "nomoto2")
    assert run_episode(policy, "nominal", seed=0).metrics["termination_reason"] == "goal"


def test_a_registered_class_named_by_a_spec_keeps_its_registration(
    tmp_path: Path, scratch_registry: None, forget_modules: list[str]
) -> None:
    file = tmp_path / "decorated.py"
    file.write_text(
        "from shipgym_baselines import register_controller\n"
        "from shipgym_baselines.classical.reference import ZeroRudder\n\n"
        "@register_controller('test_decorated_zero', applies_to=['mariner'])\n"
        "class Zero(ZeroRudder):\n"
        "    pass\n"
    )
    assert controller_label(f"{file}:Zero") == "test_decorated_zero"
    assert CONTROLLERS["test_decorated_zero"].applies_to == ("mariner",)
    assert controller_label(f"{file}:Zero") == "test_decorated_zero"  # not registered twice


class CallLog:
    """A plug-in that records what the evaluation loop hands it and sets on it."""

    name = "call_log"
    kind = "classical"

    def __init__(self) -> None:
        object.__setattr__(self, "received", [])
        object.__setattr__(self, "assigned", [])

    def __setattr__(self, attr: str, value: Any) -> None:
        self.assigned.append(attr)
        object.__setattr__(self, attr, value)

    def reset(self, context: ControllerContext, seed: int | None = None) -> None:
        self.received.append(("reset", type(context), type(seed)))

    def act(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        self.received.append(("act", type(obs), type(info)))
        return np.zeros(1, dtype=np.float32)


def test_a_plugin_gets_only_the_context_obs_and_info() -> None:
    """Fairness: the loop hands a plug-in the context at reset, obs and info at every step,
    and nothing else (no env, no true parameters set on it)."""
    policy = CallLog()
    run_episode(policy, "nominal", seed=0)
    assert policy.received[0] == ("reset", ControllerContext, int)
    assert set(policy.received[1:]) == {("act", np.ndarray, dict)}
    assert policy.assigned == []


# ------------------------------------------------------------------ entry points


def _install(site: Path, dist: str, entry_points: dict[str, str], modules: dict[str, str]) -> None:
    """What ``pip install`` of a distribution leaves on sys.path: its modules and a
    ``*.dist-info`` folder with METADATA and entry_points.txt."""
    info = site / f"{dist.replace('-', '_')}-0.1.dist-info"  # as pip names it
    info.mkdir(parents=True)
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {dist}\nVersion: 0.1\n")
    lines = "".join(f"{name} = {target}\n" for name, target in entry_points.items())
    (info / "entry_points.txt").write_text(f"[shipgym.controllers]\n{lines}")
    for name, code in modules.items():
        (site / f"{name}.py").write_text(code)


@pytest.fixture
def site(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, scratch_registry: None) -> Iterator[Path]:
    """A folder on sys.path that installed distributions go into (removed after)."""
    folder = tmp_path / "site"
    folder.mkdir()
    monkeypatch.syspath_prepend(str(folder))
    before = set(sys.modules)
    yield folder
    for name in set(sys.modules) - before:
        if name.startswith("test_plugin_"):
            del sys.modules[name]


FACTORY_MODULE = (
    POLICY_FILE
    + """

def make_mariner_steer(**settings):
    return Steer(**settings)


make_mariner_steer.applies_to = ["mariner"]
"""
)


def test_an_entry_point_is_listed_then_loaded_when_asked_for(site: Path) -> None:
    _install(
        site,
        "test-plugin-steer",
        {"test_ep_steer": "test_plugin_steer:make_mariner_steer"},
        {"test_plugin_steer": FACTORY_MODULE},
    )
    assert "test_ep_steer" in entry_point_names()
    assert "test_ep_steer" in unknown_controller("nope")  # among the valid names
    assert "test_plugin_steer" not in sys.modules  # listed, not imported
    policy, mode = make_controller("test_ep_steer", gain=1.5)
    assert "test_plugin_steer" in sys.modules
    assert (policy.name, mode, policy.gain) == ("test_ep_steer", "rudder", 1.5)
    record = CONTROLLERS["test_ep_steer"]  # registered as register_controller would
    assert record.applies_to == ("mariner",) and record.kind == "classical"
    assert not applies_to("test_ep_steer", "nomoto2")
    (result,) = evaluate("test_ep_steer", "mariner_track", [0])
    assert result.controller == "test_ep_steer"


def test_an_entry_point_module_may_register_itself(site: Path) -> None:
    module = (
        "from shipgym_baselines import register_controller\n"
        "from shipgym_baselines.classical.reference import ZeroRudder\n\n"
        "@register_controller('test_ep_self', action_mode='guidance')\n"
        "class SelfRegistered(ZeroRudder):\n"
        "    pass\n"
    )
    _install(
        site,
        "test-plugin-self",
        {"test_ep_self": "test_plugin_self:SelfRegistered"},
        {"test_plugin_self": module},
    )
    policy, mode = make_controller("test_ep_self")
    assert mode == "guidance" and type(policy).__name__ == "SelfRegistered"


def test_a_class_entry_point_gets_the_registered_name(site: Path) -> None:
    _install(
        site,
        "test-plugin-class",
        {"steer": "test_plugin_class:Steer", "test_ep_other": "test_plugin_class:Steer"},
        {"test_plugin_class": POLICY_FILE},
    )
    assert make_controller("steer")[0].name == "steer"
    with pytest.raises(ControllerError, match="declares name = 'steer'"):
        make_controller("test_ep_other")  # a class has one name: the same as its entry's


def test_broken_entry_points_are_clear_errors(site: Path) -> None:
    _install(site, "test-plugin-broken", {"test_ep_gone": "test_plugin_gone:Steer"}, {})
    _install(site, "test-plugin-one", {"test_ep_twice": "test_plugin_one:Steer"}, {})
    _install(site, "test-plugin-two", {"test_ep_twice": "test_plugin_two:Steer"}, {})
    with pytest.raises(ControllerError, match=r"entry point 'test_ep_gone'.*no module named"):
        make_controller("test_ep_gone")
    with pytest.raises(ControllerError, match="declared by several installed packages"):
        make_controller("test_ep_twice")


# ------------------------------------------------------------------ suites and runs


def test_a_suite_takes_the_long_form_and_anchors_relative_files(
    tmp_path: Path, policy_file: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    suite = _tiny_suite(
        policy_file.parent,
        [
            "pid_los",
            "steer.py:Steer",
            {"controller": "steer.py:Steer", "name": "steer_soft", "settings": {"gain": 1.0}},
            "agents/ppo_ship.zip",
            "steer_module:Steer",
        ],
    )
    monkeypatch.chdir(tmp_path)  # not the suite's folder
    assert load_suite(str(suite)).controllers == [
        "pid_los",
        f"{policy_file}:Steer",
        ControllerEntry(controller=f"{policy_file}:Steer", name="steer_soft", settings={"gain": 1}),
        str(policy_file.parent / "agents/ppo_ship.zip"),
        "steer_module:Steer",  # a module spec is imported, not read as a file
    ]
    assert anchored("/abs/steer.py:Steer", tmp_path) == "/abs/steer.py:Steer"


@pytest.mark.parametrize(
    ("entry", "message"),
    [
        ({"controller": "pid_los", "nme": "x"}, r"key 'controllers\.0\.long form\.nme': Extra"),
        ({"name": "x"}, r"key 'controllers\.0\.long form\.controller': Field required"),
        (3, r"key 'controllers\.0\.short form': Input should be a valid string"),
    ],
)
def test_a_bad_long_form_names_the_file_and_key(tmp_path: Path, entry: Any, message: str) -> None:
    with pytest.raises(ConfigError, match=message):
        load_suite(_tiny_suite(tmp_path, [entry]))


def test_long_form_settings_are_checked_before_any_episode(policy_file: Path) -> None:
    entry = ControllerEntry(controller=f"{policy_file}:Steer", settings={"gian": 1.0})
    with pytest.raises(ControllerError, match="gian"):
        check_controllers([entry])
    alias = ControllerEntry(controller="pid_los", name="lqr")
    with pytest.raises(ControllerError, match="'lqr', the name of a registered controller"):
        check_controllers([alias])
    twice = [f"{policy_file}:Steer", ControllerEntry(controller=f"{policy_file}:Steer")]
    with pytest.raises(RunError, match=r"same table name\(s\) \['steer'\]"):
        check_controllers(twice)


def test_one_class_enters_twice_under_two_names_in_worker_processes(
    tmp_path: Path, policy_file: Path, forget_modules: list[str]
) -> None:
    """The leaderboard's pool (fork) resolves each spec in its workers: two rows, two gains."""
    suite = _tiny_suite(
        policy_file.parent,
        [
            {"controller": "steer.py:Steer", "name": "steer_soft", "settings": {"gain": 1.0}},
            {"controller": "steer.py:Steer", "name": "steer_stiff", "settings": {"gain": 4.0}},
            "zero_rudder",
        ],
    )
    rows = run_leaderboard(str(suite), out_dir=tmp_path / "out", workers=2, show_progress=False)
    by_name = {r["controller"]: r for r in rows}
    assert set(by_name) == {"steer_soft", "steer_stiff", "zero_rudder"}
    assert by_name["steer_soft"]["kind"] == "classical"
    assert by_name["steer_soft"]["ace"] != by_name["steer_stiff"]["ace"]


def test_a_spec_resolves_in_a_fresh_worker_process(
    policy_file: Path, forget_modules: list[str]
) -> None:
    """A spawned worker has none of the parent's modules: the job's string is enough."""
    job = (f"{policy_file}:Steer", "nominal", EVAL_SEED_OFFSET)
    with ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("spawn")) as pool:
        remote = pool.submit(run_job, job).result()
    local = run_job(job)
    assert remote.controller == local.controller == "steer"
    assert remote.metrics["ace"] == local.metrics["ace"]


# ------------------------------------------------------------------ the docs page example


def page_blocks() -> list[tuple[str, str]]:
    """The code blocks of the docs page "Enter your controller": (marker, code), in order."""
    section = PLUGINS_PAGE.read_text()
    pattern = r"<!-- docs-test: ([^>]+?) -->\s*```\w+\n(.*?)```"
    return [(m[1], m[2]) for m in re.finditer(pattern, section, flags=re.DOTALL)]


def test_the_plugins_page_example_runs(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    scratch_registry: None,
    forget_modules: list[str],
) -> None:
    """Every block of docs/plugins.md, as written: files written, Python executed,
    ``shipgym`` lines run through the CLI (one seed, into tmp folders), the entry point
    installed as pip would."""
    blocks = page_blocks()
    kinds = [marker.split()[0] for marker, _ in blocks]
    assert {"file", "python", "shell", "entry"} <= set(kinds), kinds
    monkeypatch.chdir(tmp_path)
    monkeypatch.syspath_prepend(str(tmp_path))
    forget_modules.append("my_controller")
    commands = 0
    for marker, code in blocks:
        kind, _, arg = marker.partition(" ")
        if kind == "file":
            (tmp_path / arg).write_text(code)
        elif kind == "python":
            exec(compile(code, f"docs/plugins.md:{marker}", "exec"), {"__name__": "plugins_page"})
        elif kind == "entry":
            points = tomllib.loads(code)["project"]["entry-points"]["shipgym.controllers"]
            _install(tmp_path / "site", "my-controller", points, {})
            monkeypatch.syspath_prepend(str(tmp_path / "site"))
            for name in points:
                assert make_controller(name)[0].name == name
        elif kind == "shell":
            for line in filter(None, code.splitlines()):
                argv = shlex.split(line)
                assert argv[0] == "shipgym", line
                out = tmp_path / f"run{commands}"
                extra = ["--seeds", "1", "--workers", "1", "--no-progress", "--json"]
                assert main([*argv[1:], *extra, "--out", str(out)]) == 0, line
                commands += 1
                assert (out / "leaderboard.json").is_file()
        else:
            raise AssertionError(f"unknown docs block {marker!r}")
    assert commands >= 3
    assert "my_policy" in capsys.readouterr().out
    suite = load_suite(str(tmp_path / "my_suite.yaml"))
    labels = check_controllers(list(suite.controllers))
    assert labels == ["pid_los", "my_policy", "my_policy_stiff"]
    assert controller_kind("my_policy_soft") == "classical"
    assert CONTROLLERS["my_policy_soft"].applies_to == ("nomoto2", "mariner")

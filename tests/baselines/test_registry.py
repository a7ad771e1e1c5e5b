"""The controller registry: one registration per controller (docs/plugins.md)."""

from __future__ import annotations

import dataclasses
import pickle
import subprocess
import sys
from typing import Any

import numpy as np
import pytest

import shipgym_baselines
from shipgym.envs.context import ControllerContext
from shipgym_baselines.classical.pid import PIDLOS
from shipgym_baselines.classical.reference import ZeroRudder
from shipgym_baselines.controllers import BUILTINS as BUILTIN_TABLE
from shipgym_baselines.controllers import Builtin
from shipgym_baselines.errors import ControllerError
from shipgym_baselines.evaluation import run_episode
from shipgym_baselines.learned.plant_id.shipped import shipped_seeds
from shipgym_baselines.learned.policy import shipped_policies
from shipgym_baselines.plugins import ControllerEntry
from shipgym_baselines.policy import FAMILIES, Style
from shipgym_baselines.privileged import ORACLE, ORACLE_FROZEN, PRIVILEGED_NAMES, grants_truth
from shipgym_baselines.registry import (
    BASELINE,
    CONTROLLERS,
    applies_to,
    controller_kind,
    declared_traits,
    make_controller,
    register_controller,
    resolve_controller,
    training_seeds,
)

#: the contract: every built-in controller's name, action mode and ships (None: all)
BUILTINS = {
    "pid_los": ("rudder", None),
    "pid_lookahead_los": ("rudder", None),
    "pid_vf": ("rudder", None),
    "pid_tvvf": ("rudder", None),
    "lqr": ("rudder", None),
    "adaptive_lqr": ("rudder", None),
    "l1_backstepping": ("rudder", None),
    "adaptive_backstepping": ("rudder", None),
    "nmpc": ("rudder", None),
    "nmpc_wlssvm": ("rudder", None),
    "nmpc_lambda_lssvm": ("rudder", None),
    "nmpc_wlssvm_svf": ("rudder", None),
    "nmpc_lambda_lssvm_svf": ("rudder", None),
    "nmpc_ekf": ("rudder", None),
    "zero_rudder": ("rudder", None),
    "random": ("rudder", None),
    "oracle": ("rudder", None),
    "oracle_frozen": ("rudder", None),
    "nmpc_learned_id": ("rudder", None),
}
#: the references: shown on every scenario, never ranked
REFERENCES = {"zero_rudder", "random", "oracle", "oracle_frozen"}
#: the built-ins that are learned (registered by name, trained estimators shipped)
LEARNED = {"nmpc_learned_id"}


def _without_compute_time(metrics: dict[str, Any]) -> dict[str, Any]:
    return {k: v for k, v in metrics.items() if not k.startswith("compute_ms")}


def test_builtin_controllers_keep_their_names_modes_and_ships() -> None:
    table = {name: (r.action_mode, r.applies_to) for name, r in CONTROLLERS.items()}
    assert table == BUILTINS
    assert {controller_kind(name) for name in BUILTINS.keys() - REFERENCES - LEARNED} == {
        "classical"
    }
    assert {controller_kind(name) for name in LEARNED} == {"learned"}
    assert {controller_kind(name) for name in REFERENCES} == {"reference"}


@pytest.mark.parametrize("name", sorted(BUILTINS))
def test_made_controller_carries_its_registered_name(name: str) -> None:
    policy, mode = make_controller(name)
    assert policy.name == name
    assert mode == BUILTINS[name][0]


def test_every_controller_declares_a_family_and_a_look() -> None:
    """Every registered controller and every shipped learned agent: a family of the figures
    and a look (none is left to the name's hash)."""
    for name in [*CONTROLLERS, *shipped_policies()]:
        family, look = declared_traits(name)
        assert family in FAMILIES, name
        assert isinstance(look, Style), name
    assert {declared_traits(name)[0] for name in shipped_policies()} == {"learned"}
    assert {declared_traits(name)[0] for name in REFERENCES} == {"references"}
    assert declared_traits("my_module:MyPolicy") == (None, None)


def test_the_baseline_and_the_references_are_registered_controllers() -> None:
    assert CONTROLLERS[BASELINE].kind == "classical"
    assert CONTROLLERS[ORACLE].kind == CONTROLLERS[ORACLE_FROZEN].kind == "reference"


def test_a_registration_carries_its_family_and_look(scratch_registry: None) -> None:
    look = Style("#123456", "--", "o")
    register_controller("test_styled", lambda: ZeroRudder(), family="PID", look=look)
    assert (CONTROLLERS["test_styled"].family, CONTROLLERS["test_styled"].look) == ("PID", look)
    register_controller("test_plain", lambda: ZeroRudder())
    assert declared_traits("test_plain") == (None, None)  # the figures derive both
    with pytest.raises(ValueError, match="family must be one of"):
        register_controller("test_bad_family", ZeroRudder, family="MPC")
    with pytest.raises(TypeError, match=r"look is a shipgym_baselines\.policy\.Style"):
        register_controller("test_bad_look", ZeroRudder, look=("#000000", "-", "o"))  # type: ignore[arg-type]
    assert not {"test_bad_family", "test_bad_look"} & set(CONTROLLERS)


def test_the_traits_are_read_without_importing_a_controller() -> None:
    """In a fresh interpreter, every built-in's traits come from the table of entry points:
    no controller module is imported until one is made, and then only its own."""
    code = (
        "import sys\n"
        "from shipgym_baselines.registry import CONTROLLERS, make_controller, training_seeds\n"
        "from shipgym_baselines.registry import controller_kind, declared_traits, applies_to\n"
        "from shipgym_baselines.privileged import grants_truth\n"
        "for name, record in CONTROLLERS.items():\n"
        "    controller_kind(name), declared_traits(name), training_seeds(name)\n"
        "    applies_to(name, 'mariner'), grants_truth(name)\n"
        "def controllers():\n"
        "    return sorted(m for m in sys.modules if m.startswith(('shipgym_baselines.classical.',"
        " 'shipgym_baselines.learned.plant_id.controller')))\n"
        "assert controllers() == [], controllers()\n"
        "policy, mode = make_controller('pid_los')\n"
        "print(policy.name, mode, *controllers())\n"
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert run.stdout.split() == [
        "pid_los",
        "rudder",
        "shipgym_baselines.classical.drift",
        "shipgym_baselines.classical.pid",
    ]


@pytest.mark.parametrize("builtin", BUILTIN_TABLE, ids=lambda b: b.name)
def test_each_entry_point_names_a_class_with_the_registered_traits(builtin: Builtin) -> None:
    """The table's entry point is a Policy class that declares the table's name and kind
    (its own attributes, read by the class itself)."""
    cls = CONTROLLERS[builtin.name].factory
    assert isinstance(cls, type) and f"{cls.__module__}:{cls.__qualname__}" == builtin.entry_point
    assert (cls.name, cls.kind) == (builtin.name, builtin.kind)


def test_the_learned_built_in_lists_its_shipped_seeds_without_its_module() -> None:
    assert training_seeds("nmpc_learned_id") == list(shipped_seeds() or (None,))


def test_only_the_references_named_as_such_read_the_truth(scratch_registry: None) -> None:
    assert PRIVILEGED_NAMES == (ORACLE, ORACLE_FROZEN)
    assert {name for name, r in CONTROLLERS.items() if r.privileged} == {ORACLE, ORACLE_FROZEN}
    assert grants_truth(ORACLE) and grants_truth(resolve_controller(ORACLE_FROZEN))
    renamed = ControllerEntry(controller=ORACLE, name="my_oracle")
    with_settings = ControllerEntry(controller=ORACLE, settings={"settings": None})
    assert not grants_truth(renamed) and not resolve_controller(renamed).privileged
    assert not grants_truth(with_settings) and not grants_truth("pid_los")
    spec = resolve_controller("shipgym_baselines.classical.oracle:Oracle")  # the same class
    assert spec.name == ORACLE and not grants_truth(spec)
    # a record built by hand that says privileged is not the reference's own record
    own = resolve_controller(ORACLE)
    for forged in (
        dataclasses.replace(resolve_controller("pid_los"), privileged=True),
        dataclasses.replace(own, name="my_oracle"),
        dataclasses.replace(own, settings={"horizon": 3}),
        dataclasses.replace(own, entry_point="shipgym_baselines.classical.pid:PIDLOS"),
    ):
        assert not grants_truth(forged), forged


def test_a_record_is_resolved_once_and_crosses_a_process_pool(scratch_registry: None) -> None:
    """A resolved record is its own resolution; pickled it leaves its loaded factory behind
    and the process that unpickles it loads the same controller, settings bound."""
    stiff = resolve_controller(
        ControllerEntry(controller="pid_los", name="pid_stiff", settings={"natural_frequency": 2.0})
    )
    assert resolve_controller(stiff) is stiff and stiff.loaded is PIDLOS
    copy = pickle.loads(pickle.dumps(stiff))
    assert copy == stiff and copy.loaded is None
    policy, mode = make_controller(copy)
    assert (type(policy), policy.name, mode, policy.natural_frequency) == (
        PIDLOS,
        "pid_stiff",
        "rudder",
        2.0,
    )
    register_controller("test_lambda", lambda: ZeroRudder())  # found again by its name
    made, _ = make_controller(pickle.loads(pickle.dumps(resolve_controller("test_lambda"))))
    assert isinstance(made, ZeroRudder) and made.name == "test_lambda"


def test_the_registry_is_read_only() -> None:
    with pytest.raises(TypeError):
        CONTROLLERS["pid_los"] = CONTROLLERS["lqr"]  # type: ignore[index]


def test_register_controller_of_the_package_registers(scratch_registry: None) -> None:
    @shipgym_baselines.register_controller("test_from_the_package")
    class HoldZero(ZeroRudder):
        """Zero rudder under another name."""

    assert HoldZero.name == "test_from_the_package"
    assert make_controller("test_from_the_package")[0].name == "test_from_the_package"


def test_decorator_registers_a_class_and_gives_it_the_name(scratch_registry: None) -> None:
    @register_controller("test_hold_zero")
    class HoldZero(ZeroRudder):
        """Zero rudder under another name (no name attribute of its own)."""

    assert HoldZero.name == "test_hold_zero"
    assert ZeroRudder.name == "zero_rudder"  # the parent keeps its own
    assert CONTROLLERS["test_hold_zero"].factory is HoldZero
    policy, mode = make_controller("test_hold_zero")
    assert isinstance(policy, HoldZero) and mode == "rudder"


def test_decorator_on_a_factory_function(scratch_registry: None) -> None:
    @register_controller("test_pid_vyshnegradsky")
    def pid_vyshnegradsky(**settings: Any) -> PIDLOS:
        return PIDLOS(tuning="vyshnegradsky", **settings)

    assert callable(pid_vyshnegradsky)  # the decorator returns the function
    policy, _ = make_controller("test_pid_vyshnegradsky")
    assert policy.name == "test_pid_vyshnegradsky" and policy.tuning == "vyshnegradsky"
    assert PIDLOS.name == "pid_los"  # the class is not renamed by a factory's registration


def test_user_factory_runs_through_the_loop_beside_a_builtin(scratch_registry: None) -> None:
    """A factory registered at runtime is made by name and scored by the evaluation loop."""

    def stiff_pid(**settings: Any) -> PIDLOS:
        return PIDLOS(natural_frequency=2.0, **settings)

    assert register_controller("test_stiff_pid", stiff_pid) is stiff_pid
    user, user_mode = make_controller("test_stiff_pid")
    builtin, builtin_mode = make_controller("pid_los")
    mine = run_episode(user, "nominal", seed=0, action_mode=user_mode)
    theirs = run_episode(builtin, "nominal", seed=0, action_mode=builtin_mode)
    assert (mine.controller, theirs.controller) == ("test_stiff_pid", "pid_los")
    assert mine.metrics["termination_reason"] == theirs.metrics["termination_reason"] == "goal"
    # ωn = 2 rad/s instead of 1: other gains, another episode
    assert mine.metrics["controller_stats"]["pid_kp"] > theirs.metrics["controller_stats"]["pid_kp"]
    assert mine.metrics["ace"] != theirs.metrics["ace"]


def test_a_renamed_controller_scores_as_the_original(scratch_registry: None) -> None:
    """Registration changes the name only: the same actions give the same metrics."""
    register_controller("test_zero", lambda: ZeroRudder())  # a class has one name: alias it
    policy, _ = make_controller("test_zero")
    renamed = run_episode(policy, "nominal", seed=0)
    original = run_episode(make_controller("zero_rudder")[0], "nominal", seed=0)
    assert _without_compute_time(renamed.metrics) == _without_compute_time(original.metrics)


def test_registered_action_mode_reaches_the_env(scratch_registry: None) -> None:
    """A zero action in guidance mode is the env's PID LOS: it reaches the goal, where the
    zero rudder (rudder mode) leaves the corridor."""
    register_controller("test_zero_guidance", lambda: ZeroRudder(), action_mode="guidance")
    policy, mode = make_controller("test_zero_guidance")
    assert mode == policy.action_mode == "guidance"
    assert run_episode(policy, "nominal", seed=0).metrics["termination_reason"] == "goal"
    zero, _ = make_controller("zero_rudder")
    assert run_episode(zero, "nominal", seed=0).metrics["termination_reason"] != "goal"


def test_a_controller_refuses_an_env_in_another_action_mode() -> None:
    policy, _ = make_controller("lqr")
    with pytest.raises(ValueError, match="action_mode 'rudder'"):
        run_episode(policy, "nominal", seed=0, action_mode="guidance")


def test_duplicate_name_names_both_factories(scratch_registry: None) -> None:
    def other_pid() -> PIDLOS:
        return PIDLOS()

    with pytest.raises(ValueError, match=r"'pid_los' is taken.*PIDLOS.*other_pid"):
        register_controller("pid_los", other_pid)
    assert CONTROLLERS["pid_los"].factory is PIDLOS  # unchanged


def test_registering_the_same_controller_again_is_harmless() -> None:
    assert register_controller("pid_los", PIDLOS) is PIDLOS
    assert CONTROLLERS["pid_los"].factory is PIDLOS


def test_a_class_declaring_another_name_is_refused(scratch_registry: None) -> None:
    class Named:
        name = "something_else"
        kind = "classical"

        def reset(self, context: ControllerContext, seed: int | None = None) -> None: ...

        def act(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
            return np.zeros(1, dtype=np.float32)

    with pytest.raises(ValueError, match="declares name = 'something_else'"):
        register_controller("test_named", Named)
    assert "test_named" not in CONTROLLERS


def test_bad_registrations_are_clear_errors(scratch_registry: None) -> None:
    with pytest.raises(ValueError, match="action_mode must be one of"):
        register_controller("test_bad_mode", ZeroRudder, action_mode="thrust")
    with pytest.raises(ValueError, match=r"unknown ship\(s\) \['titanic'\]"):
        register_controller("test_bad_ship", ZeroRudder, applies_to=("titanic",))
    with pytest.raises(TypeError, match="not a string"):
        register_controller("test_str_ship", ZeroRudder, applies_to="mariner")
    assert not {"test_bad_mode", "test_bad_ship", "test_str_ship"} & set(CONTROLLERS)


def test_unknown_controller_lists_valid_names() -> None:
    with pytest.raises(KeyError, match="pid_los") as err:
        make_controller("nope")
    assert all(name in str(err.value) for name in BUILTINS)
    assert "ppo" in str(err.value)  # the shipped learned policies too


def test_applies_to_follows_the_registration(scratch_registry: None) -> None:
    for name in ("nmpc", "nmpc_wlssvm", "nmpc_lambda_lssvm"):  # the NMPC family: every ship
        assert all(applies_to(name, s) for s in ("nomoto2", "mariner", "blanke", "esso_osaka"))
    assert applies_to("pid_los", "mariner") and applies_to("ppo", "mariner")
    register_controller("test_mariner_only", lambda: ZeroRudder(), applies_to=["mariner"])
    assert CONTROLLERS["test_mariner_only"].applies_to == ("mariner",)
    assert applies_to("test_mariner_only", "mariner")
    assert not applies_to("test_mariner_only", "nomoto2")


def test_learned_policies_resolve_by_name() -> None:
    policy, mode = make_controller("ppo")
    assert policy.kind == controller_kind("ppo") == "learned"
    assert mode == policy.action_mode == policy.meta["action_mode"]


def test_the_long_form_renames_and_sets_a_registered_controller(scratch_registry: None) -> None:
    """One controller, two table names, two settings; the alias keeps mode, ships, kind."""
    stiff = ControllerEntry(
        controller="pid_los", name="pid_stiff", settings={"natural_frequency": 2.0}
    )
    policy, mode = make_controller(stiff)
    assert (policy.name, mode, type(policy)) == ("pid_stiff", "rudder", PIDLOS)
    assert PIDLOS.name == "pid_los"  # the instance is renamed, not the class
    mine = run_episode(policy, "nominal", seed=0)
    theirs = run_episode(make_controller("pid_los")[0], "nominal", seed=0)
    assert (mine.controller, theirs.controller) == ("pid_stiff", "pid_los")
    assert mine.metrics["controller_stats"]["pid_kp"] > theirs.metrics["controller_stats"]["pid_kp"]
    register_controller("test_nomoto2_only", lambda: ZeroRudder(), applies_to=["nomoto2"])
    alias = resolve_controller(ControllerEntry(controller="test_nomoto2_only", name="only_2"))
    assert alias.applies_to == ("nomoto2",) and controller_kind("only_2") == "classical"
    assert not applies_to("only_2", "mariner")


def test_unknown_settings_are_named_before_anything_is_made() -> None:
    with pytest.raises(ControllerError, match=r"'pid_los'.*natural_frequncy"):
        resolve_controller(ControllerEntry(controller="pid_los", settings={"natural_frequncy": 2}))

"""Tests for the config resolver, the YAML + validation loader and the packaging of configs/."""

from __future__ import annotations

import shutil
import subprocess
import sys
import zipfile
from importlib.resources import files
from pathlib import Path

import pytest
from pydantic import Field

from shipgym.config import (
    KINDS,
    ConfigError,
    StrictModel,
    deep_merge,
    is_path,
    list_names,
    load_yaml_model,
    resolve,
)
from shipgym.errors import ShipgymError

REPO = Path(__file__).resolve().parents[2]


class _Leg(StrictModel):
    length: float = Field(1.0, gt=0)
    turn_deg: float = 0.0


class _Route(StrictModel):
    name: str
    legs: dict[str, _Leg] = Field(default_factory=dict)
    speed: float = 1.0


# ------------------------------------------------------------------ the resolver


@pytest.mark.parametrize("kind", sorted(KINDS))
def test_names_are_the_files_of_the_top_level_configs_folder(kind: str) -> None:
    """configs/ is the single source of the packaged catalogue."""
    on_disk = sorted(p.stem for p in (REPO / "configs" / kind).glob("*.yaml"))
    assert on_disk and list_names(kind) == on_disk


def test_a_name_is_the_packaged_file_found_through_importlib_resources() -> None:
    found = resolve("scenarios", "rudder_aging")
    packaged = files("shipgym.configs") / "scenarios" / "rudder_aging.yaml"
    assert found == packaged
    assert found.read_text() == (REPO / "configs/scenarios/rudder_aging.yaml").read_text()


def test_every_config_folder_is_a_kind() -> None:
    folders = {p.name for p in (REPO / "configs").iterdir() if p.is_dir() and p.name[0] != "_"}
    assert folders == set(KINDS)


@pytest.mark.parametrize(
    ("text", "path"),
    [
        ("nominal", False),
        ("heldout:3", False),
        ("my.yaml", True),
        ("my.yml", True),
        ("sub/my", True),
        ("./nominal", True),
    ],
)
def test_what_counts_as_a_path(text: str, path: bool) -> None:
    assert is_path(text) is path


def test_a_path_is_that_file(tmp_path: Path) -> None:
    file = tmp_path / "mine.yaml"
    file.write_text("name: mine\n")
    assert resolve("suites", str(file)) == file
    assert resolve("suites", file) == file


def test_a_relative_path_is_read_against_relative_to(tmp_path: Path, monkeypatch) -> None:
    (tmp_path / "suite_dir" / "scen").mkdir(parents=True)
    suite = tmp_path / "suite_dir" / "my_suite.yaml"
    suite.write_text("name: x\n")
    target = tmp_path / "suite_dir" / "scen" / "a.yaml"
    target.write_text("name: a\n")
    monkeypatch.chdir(tmp_path)  # not where the file is
    assert resolve("scenarios", "scen/a.yaml", relative_to=suite) == target  # a file's folder
    assert resolve("scenarios", "scen/a.yaml", relative_to=suite.parent) == target
    with pytest.raises(ConfigError, match="scenario file not found"):
        resolve("scenarios", "scen/a.yaml")  # without relative_to: the working directory
    monkeypatch.chdir(tmp_path / "suite_dir")
    assert resolve("scenarios", "scen/a.yaml").resolve() == target


def test_an_absolute_path_ignores_relative_to(tmp_path: Path) -> None:
    file = tmp_path / "a.yaml"
    file.write_text("name: a\n")
    assert resolve("scenarios", str(file), relative_to=tmp_path / "elsewhere") == file


def test_unknown_name_names_kind_request_and_valid_names() -> None:
    with pytest.raises(ConfigError) as info:
        resolve("distributions", "trian")
    msg = str(info.value)
    assert "unknown distribution 'trian'" in msg and "configs/distributions" in msg
    assert "valid: heldout, inrange, train, validation" in msg


def test_missing_file_names_the_file(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match=r"agent config file not found: .*nowhere\.yaml"):
        resolve("agents", str(tmp_path / "nowhere.yaml"))


def test_unknown_kind_lists_the_kinds() -> None:
    with pytest.raises(ConfigError, match=r"unknown config kind 'controllers'.*scenarios"):
        resolve("controllers", "pid")


def test_the_error_type_is_the_callers() -> None:
    class MyError(ValueError):
        pass

    with pytest.raises(MyError):
        resolve("suites", "nope", error=MyError)
    assert issubclass(ConfigError, ShipgymError) and issubclass(ConfigError, ValueError)


# ------------------------------------------------------------------ the loader


def test_load_yaml_model_validates(tmp_path: Path) -> None:
    file = tmp_path / "r.yaml"
    file.write_text("name: r\nlegs: {a: {length: 2.5}}\n")
    route = load_yaml_model(file, _Route)
    assert route == _Route(name="r", legs={"a": _Leg(length=2.5)})


def test_malformed_yaml_names_file_and_line(tmp_path: Path) -> None:
    file = tmp_path / "broken.yaml"
    file.write_text("name: r\nlegs:\n  a: {length: 2\nspeed: 3\n")  # flow mapping not closed
    with pytest.raises(ConfigError, match="malformed YAML") as info:
        load_yaml_model(file, _Route)
    msg = str(info.value)
    assert msg.startswith(f"{file}, line 4,")  # where the parser gives up


def test_bad_key_and_unknown_key_are_named(tmp_path: Path) -> None:
    file = tmp_path / "r.yaml"
    file.write_text("name: r\nlegs: {a: {length: -1}}\nsped: 2\n")
    with pytest.raises(ConfigError) as info:
        load_yaml_model(file, _Route)
    msg = str(info.value)
    assert f"{file}: key 'legs.a.length'" in msg and "greater than 0" in msg
    assert f"{file}: key 'sped'" in msg and "Extra inputs" in msg


def test_a_non_mapping_file_is_an_error_naming_it(tmp_path: Path) -> None:
    file = tmp_path / "list.yaml"
    file.write_text("- a\n- b\n")
    with pytest.raises(ConfigError, match=r"list\.yaml: expected a mapping.*got list"):
        load_yaml_model(file, _Route)


# ------------------------------------------------------------------ overrides


def test_deep_merge_merges_mappings_and_replaces_the_rest() -> None:
    base = {"a": {"x": 1, "y": [1, 2]}, "b": 2}
    assert deep_merge(base, {"a": {"y": [3]}, "c": 4}) == {"a": {"x": 1, "y": [3]}, "b": 2, "c": 4}
    assert base == {"a": {"x": 1, "y": [1, 2]}, "b": 2}  # untouched


def test_with_overrides_is_a_validated_deep_merge() -> None:
    route = _Route(name="r", legs={"a": _Leg(length=2.0, turn_deg=30.0)}, speed=2.0)
    new = route.with_overrides({"legs": {"a": {"length": 3.0}, "b": {}}})
    assert new == _Route(
        name="r", legs={"a": _Leg(length=3.0, turn_deg=30.0), "b": _Leg()}, speed=2.0
    )
    assert route.legs["a"].length == 2.0
    assert route.with_overrides(drop=["speed", "legs.a.turn_deg"]) == _Route(
        name="r", legs={"a": _Leg(length=2.0)}
    )
    with pytest.raises(ConfigError, match=r"here: key 'legs\.a\.length'"):
        route.with_overrides({"legs": {"a": {"length": 0.0}}}, origin="here")
    with pytest.raises(ConfigError, match=r"cannot drop 'legs\.c'"):
        route.with_overrides(drop=["legs.c"])


# ------------------------------------------------------------------ packaging


@pytest.fixture(scope="module")
def wheel_files(tmp_path_factory) -> set[str]:
    """The file names in a wheel built from a copy of the sources (the checkout untouched)."""
    src = tmp_path_factory.mktemp("src")
    ignore = shutil.ignore_patterns("__pycache__", "*.egg-info")
    for folder in ("shipgym", "baselines", "configs"):
        shutil.copytree(REPO / folder, src / folder, ignore=ignore)
    for file in ("pyproject.toml", "setup.py", "README.md"):
        shutil.copy(REPO / file, src / file)
    out = tmp_path_factory.mktemp("wheel")
    command = [sys.executable, "-m", "pip", "wheel", str(src), "-w", str(out), "-q", "--no-deps"]
    subprocess.run(command, check=True, capture_output=True, cwd=src)
    (wheel,) = out.glob("shipgym-*.whl")
    with zipfile.ZipFile(wheel) as archive:
        return set(archive.namelist())


def _files(folder: Path, pattern: str = "*") -> list[Path]:
    return [p for p in folder.rglob(pattern) if p.is_file() and "__pycache__" not in p.parts]


def test_the_wheel_holds_every_module(wheel_files: set[str]) -> None:
    """Subpackages are found on disk (setup.py): none is left out of the wheel."""
    modules = [
        f"{package}/{p.relative_to(REPO / top).as_posix()}"
        for package, top in (("shipgym", "shipgym"), ("shipgym_baselines", "baselines"))
        for p in _files(REPO / top, "*.py")
    ]
    assert modules and set(modules) <= wheel_files


def test_the_wheel_installs_only_our_top_level_names(wheel_files: set[str]) -> None:
    """No top-level import package that could collide with another distribution's
    (``baselines`` is OpenAI Baselines'): only shipgym and shipgym_baselines."""
    tops = {
        name.split("/")[0]
        for name in wheel_files
        if not name.split("/")[0].endswith((".dist-info", ".data"))
    }
    assert tops == {"shipgym", "shipgym_baselines"}, tops


def test_the_wheel_holds_configs_as_package_data(wheel_files: set[str]) -> None:
    """configs/ (the single source) is installed as shipgym/configs."""
    configs = [p.relative_to(REPO).as_posix() for p in _files(REPO / "configs", "*.yaml")]
    assert configs and {f"shipgym/{c}" for c in configs} <= wheel_files


def test_the_wheel_holds_the_shipped_policies(wheel_files: set[str]) -> None:
    folder = REPO / "baselines"
    policies = [
        f"shipgym_baselines/{p.relative_to(folder).as_posix()}"
        for p in _files(folder / "learned" / "policies")
    ]
    assert policies and set(policies) <= wheel_files

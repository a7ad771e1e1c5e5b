"""shipgym.codegen: CasADi functions compiled to C once, cached on disk, same results."""

from __future__ import annotations

import hashlib
import io
import json
import multiprocessing
import os
import shutil
import subprocess
import sys
from pathlib import Path

import casadi as ca
import numpy as np
import pytest

from shipgym import codegen
from shipgym.models.nomoto2 import Nomoto2

#: these tests read the notice lines, which the suite silences
pytestmark = pytest.mark.usefixtures("loud")

needs_compiler = pytest.mark.skipif(
    shutil.which("gcc") is None and shutil.which("cc") is None, reason="no C compiler"
)


@pytest.fixture
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A fresh ``$SHIPGYM_CACHE`` with compilation enabled."""
    monkeypatch.setenv("SHIPGYM_CACHE", str(tmp_path))
    monkeypatch.delenv("SHIPGYM_NO_COMPILE", raising=False)
    return tmp_path


def _step() -> ca.Function:
    """nomoto2's RK4 step: sin, cos, products and sums of the model's one rhs."""
    return Nomoto2().casadi_step(0.01)


def _random_inputs(rng: np.random.Generator) -> list[np.ndarray]:
    model = Nomoto2()
    x = rng.normal(size=model.n_states)
    u = rng.uniform(-0.5, 0.5, size=1)
    w = rng.normal(scale=0.1, size=model.n_disturbances)
    p = model.params.to_vector() * rng.uniform(0.5, 1.5, size=model.n_params)
    return [x, u, w, p]


def test_cache_dir_follows_the_environment(cache: Path) -> None:
    assert codegen.cache_dir() == cache


@needs_compiler
def test_compiled_function_equals_the_vm_bit_for_bit(cache: Path) -> None:
    vm = _step()
    fast = codegen.compiled(vm)
    assert fast is not vm and list(cache.glob("*.so"))
    rng = np.random.default_rng(0)
    for _ in range(20):
        args = _random_inputs(rng)
        np.testing.assert_array_equal(np.array(fast(*args)), np.array(vm(*args)))


@needs_compiler
def test_the_cached_library_is_reused(cache: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A second request for the same code and flags loads the cached library: no compiler
    run, the file untouched."""
    codegen.compiled(_step())
    (library,) = cache.glob("*.so")
    stamp = library.stat().st_mtime_ns

    def no_compiler(*args: object, **kwargs: object) -> None:
        raise AssertionError("the compiler ran although the library was cached")

    monkeypatch.setattr(subprocess, "run", no_compiler)
    again = codegen.compiled(_step())
    assert list(cache.glob("*.so")) == [library] and library.stat().st_mtime_ns == stamp
    args = _random_inputs(np.random.default_rng(1))
    np.testing.assert_array_equal(np.array(again(*args)), np.array(_step()(*args)))


@needs_compiler
def test_other_flags_compile_another_library(cache: Path) -> None:
    codegen.compiled(_step())
    codegen.compiled(_step(), flags=("-O0",))
    assert len(list(cache.glob("*.so"))) == 2


def test_no_compile_returns_the_function_itself(
    cache: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("SHIPGYM_NO_COMPILE", "1")
    function = _step()
    assert codegen.compiled(function) is function
    assert not list(cache.iterdir())


def test_without_a_compiler_the_function_is_returned(
    cache: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(shutil, "which", lambda name: None)
    function = _step()
    assert codegen.compiled(function) is function


def test_a_failed_compilation_warns_and_returns_the_function(
    cache: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(shutil, "which", lambda name: "/usr/bin/false-compiler")

    def failing(command: list[str], **kwargs: object) -> None:
        raise subprocess.CalledProcessError(1, command)

    monkeypatch.setattr(subprocess, "run", failing)
    function = _step()
    with pytest.warns(UserWarning, match="using CasADi's VM"):
        assert codegen.compiled(function) is function
    assert not list(cache.glob("*.so"))


def test_the_user_cache_folder_follows_the_environment(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """$SHIPGYM_CACHE_DIR, else $XDG_CACHE_HOME/shipgym, else ~/.cache/shipgym; compiled
    libraries go there unless $SHIPGYM_CACHE names their own folder."""
    monkeypatch.setenv("SHIPGYM_CACHE_DIR", str(tmp_path / "mine"))
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    monkeypatch.delenv("SHIPGYM_CACHE")
    assert codegen.user_cache_dir() == codegen.cache_dir() == tmp_path / "mine"
    monkeypatch.delenv("SHIPGYM_CACHE_DIR")
    assert codegen.user_cache_dir() == tmp_path / "xdg" / "shipgym"
    monkeypatch.delenv("XDG_CACHE_HOME")
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    assert codegen.user_cache_dir() == tmp_path / "home" / ".cache" / "shipgym"
    monkeypatch.setenv("SHIPGYM_CACHE", str(tmp_path / "libs"))
    assert codegen.cache_dir() == tmp_path / "libs"
    assert codegen.user_cache_dir() == tmp_path / "home" / ".cache" / "shipgym"


@needs_compiler
def test_a_compilation_is_announced_in_one_line_on_stderr(
    cache: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    """A needed compilation prints one line on stderr (what, ≈ seconds, where cached);
    nothing on stdout; a cached library prints nothing."""
    codegen.compiled(_step(), what="the nomoto2 step")
    out, err = capfd.readouterr()
    assert out == ""
    assert err == (
        f"shipgym: compiling the nomoto2 step to C (one-off, ≈ 1 s; cached in {cache})\n"
    )
    codegen.compiled(_step(), what="the nomoto2 step")
    assert capfd.readouterr() == ("", "")


@needs_compiler
def test_functions_compiled_together_are_announced_together(
    cache: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    """``compiled_all``: one line for all the compilations it needs, its estimate from the
    size of their C code (:data:`~shipgym.codegen.COMPILE_BYTES_PER_S`)."""
    step = _step()
    x, u = ca.SX.sym("x", 4), ca.SX.sym("u", 1)
    other = ca.Function("nomoto2_twice", [x, u], [2 * x + u])
    fast = codegen.compiled_all([step, other], what="two functions")
    assert all(f is not g for f, g in zip(fast, [step, other], strict=True))
    (line,) = capfd.readouterr().err.splitlines()
    assert line.startswith("shipgym: compiling two functions to C (one-off, ≈ ")
    assert len(list(cache.glob("*.so"))) == 2


def _compile_tiny(cache: str, barrier: object, results: object) -> None:
    """In a child process: compile a tiny function into ``cache`` after ``barrier``; put
    (what it wrote on stderr, whether it got a library, its value at 3) on ``results``."""
    import os

    os.environ["SHIPGYM_CACHE"] = cache
    os.environ.pop("SHIPGYM_NO_COMPILE", None)
    x = ca.SX.sym("x")
    vm = ca.Function("tiny_square", [x], [x * x + 1])
    sys.stderr = err = io.StringIO()
    barrier.wait()  # type: ignore[attr-defined]
    fast = codegen.compiled(vm, what="the tiny function")
    results.put((err.getvalue(), fast is not vm, float(fast(3.0))))  # type: ignore[attr-defined]


@needs_compiler
def test_two_processes_compile_a_function_once(tmp_path: Path) -> None:
    """Two processes asking for the same library at once into an empty cache: one compiles
    and announces it, the other waits for the lock and loads the published library."""
    ctx = multiprocessing.get_context("spawn")
    barrier, results = ctx.Barrier(2), ctx.Queue()
    children = [
        ctx.Process(target=_compile_tiny, args=(str(tmp_path), barrier, results)) for _ in range(2)
    ]
    for child in children:
        child.start()
    outcomes = [results.get(timeout=120) for _ in children]
    for child in children:
        child.join(timeout=60)
        assert child.exitcode == 0
    announced = [line for err, _, _ in outcomes for line in err.splitlines()]
    assert len(announced) == 1 and announced[0].startswith(
        "shipgym: compiling the tiny function to C"
    )
    assert [(library, value) for _, library, value in outcomes] == [(True, 10.0)] * 2
    (library,) = tmp_path.glob("*.so")
    assert (tmp_path / f"{library.name}.lock").is_file()


def test_the_estimate_grows_with_the_code_size() -> None:
    """Linear at the measured speed up to 1.2 MB of C, in proportion to the size beyond
    (the NMPC's 2.5 MB Jacobian took 47 s)."""
    assert codegen.compile_seconds(170_000) == pytest.approx(1.7)
    assert codegen.compile_seconds(1_200_000) == pytest.approx(12)
    assert codegen.compile_seconds(2_460_065) == pytest.approx(50.4, abs=0.1)
    line = codegen.compile_message("the mariner plant", 26.2, Path("/c"))
    assert line == "shipgym: compiling the mariner plant to C (one-off, ≈ 26 s; cached in /c)"


@needs_compiler
def test_a_library_is_recorded_when_it_is_compiled(cache: Path) -> None:
    """Beside each library: its size and SHA-256, as the check before loading reads them."""
    codegen.compiled(_step())
    (library,) = cache.glob("*.so")
    record = json.loads(codegen.record_path(library).read_text())
    assert record == {
        "size": library.stat().st_size,
        "sha256": hashlib.sha256(library.read_bytes()).hexdigest(),
    }
    assert codegen.library_problem(library) is None


@needs_compiler
@pytest.mark.parametrize("damage", ["truncated", "flipped", "unrecorded"])
def test_a_damaged_library_is_compiled_again_and_named(
    cache: Path, capfd: pytest.CaptureFixture[str], damage: str
) -> None:
    """A library cut to 3,000 bytes (loading it is a SIGBUS), with a byte changed, or
    without its record is never loaded: it is compiled again, named in one line."""
    codegen.compiled(_step())
    (library,) = cache.glob("*.so")
    good = library.read_bytes()
    capfd.readouterr()
    if damage == "truncated":
        os.truncate(library, 3000)
    elif damage == "flipped":
        library.write_bytes(good[:-1] + bytes([good[-1] ^ 1]))
    else:
        codegen.record_path(library).unlink()
    why = {
        "truncated": f"is 3000 bytes, {len(good)} recorded",
        "flipped": "differs from its recorded SHA-256",
        "unrecorded": "has no record of its size and SHA-256",
    }[damage]
    assert codegen.library_problem(library) == why
    fast = codegen.compiled(_step())
    first = capfd.readouterr().err.splitlines()[0]
    assert first == f"shipgym: the cached library {library} {why}: compiling it again"
    assert library.read_bytes() == good and codegen.library_problem(library) is None
    args = _random_inputs(np.random.default_rng(2))
    np.testing.assert_array_equal(np.array(fast(*args)), np.array(_step()(*args)))

"""Compile CasADi functions to C once per machine and cache the shared library on disk.

CasADi's virtual machine evaluates an SX graph at a few ns per instruction; the same graph
compiled by a C compiler runs 5–8× faster.  :func:`compiled` generates the C code, hashes
it, compiles it with ``gcc -O1`` into :func:`cache_dir` unless a library with that hash is
already there, and loads it with ``casadi.external``.  A compilation that is needed is
announced first, in one line on stderr (what, an estimate of its seconds from the size of
the C code: :func:`compile_seconds`, where it is cached).  Without a compiler, or if
anything fails, it returns the original function (same results, slower) and says why once
through ``warnings``.  Compiling a library is exclusive across processes: a process holds
an ``fcntl`` lock on ``<library>.lock`` beside it while it compiles, and a process that
waited for the lock loads the library the other one published instead of compiling it (so
only the process that compiles announces it).  The lock files stay in the cache folder.

A library is loaded only once it is checked: its size and SHA-256 are recorded at compile
time in a sidecar ``<library>.json`` (written atomically after the library), and a library
whose size or hash differs from the record, or that has none, is never loaded (a truncated
shared library kills the process with SIGBUS when it is mapped).  It is compiled again,
with one line on stderr naming the file (:func:`library_problem`).

The per-user cache folder (:func:`user_cache_dir`) is ``$SHIPGYM_CACHE_DIR`` if set, else
``$XDG_CACHE_HOME/shipgym``, else ``~/.cache/shipgym``; compiled libraries sit at its top
(``$SHIPGYM_CACHE``, if set, names their folder alone).  Deleting the folder clears it.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import shutil
import subprocess
import tempfile
import warnings
from collections.abc import Iterator, Sequence
from pathlib import Path

import casadi as ca

from shipgym.notices import duration, notice

#: the environment variable naming the per-user cache folder
CACHE_DIR_ENV = "SHIPGYM_CACHE_DIR"
#: gcc -O1's speed on CasADi's generated C up to :data:`COMPILE_LINEAR_BYTES` of source
#: [bytes/s]: 100–270 kB/s measured on the project's 2-core machine (the plants and the
#: oracle's and NMPC's solvers); the slow end, so an estimate is rather long than short
COMPILE_BYTES_PER_S = 100e3
#: beyond this size [bytes] a file compiles more slowly, in proportion to its size (the
#: NMPC's 2.5 MB Jacobian of nomoto2's paper settings: 47 s, 52 kB/s)
COMPILE_LINEAR_BYTES = 1.2e6


def user_cache_dir() -> Path:
    """The per-user cache folder: ``$SHIPGYM_CACHE_DIR``, else ``$XDG_CACHE_HOME/shipgym``,
    else ``~/.cache/shipgym``."""
    if os.environ.get(CACHE_DIR_ENV):
        return Path(os.environ[CACHE_DIR_ENV])
    if os.environ.get("XDG_CACHE_HOME"):
        return Path(os.environ["XDG_CACHE_HOME"]) / "shipgym"
    return Path.home() / ".cache" / "shipgym"


def cache_dir() -> Path:
    """The compiled libraries' folder: ``$SHIPGYM_CACHE`` if set, else :func:`user_cache_dir`."""
    if os.environ.get("SHIPGYM_CACHE"):
        return Path(os.environ["SHIPGYM_CACHE"])
    return user_cache_dir()


def compile_seconds(size: int) -> float:
    """The estimated seconds to compile ``size`` bytes of C (one file)."""
    return size / COMPILE_BYTES_PER_S * max(1.0, size / COMPILE_LINEAR_BYTES)


def compile_message(what: str, seconds: float, folder: Path) -> str:
    """The line announcing a compilation of ``what`` estimated at ``seconds`` [s]."""
    return f"shipgym: compiling {what} to C (one-off, ≈ {duration(seconds)}; cached in {folder})"


def compiled(
    function: ca.Function, flags: tuple[str, ...] = ("-O1",), what: str | None = None
) -> ca.Function:
    """``function`` compiled to a cached shared library, or itself if that is impossible;
    ``what``: its name in the announcement (default: the function's)."""
    return compiled_all([function], flags, what)[0]


def compiled_all(
    functions: Sequence[ca.Function], flags: tuple[str, ...] = ("-O1",), what: str | None = None
) -> list[ca.Function]:
    """Each of ``functions`` as :func:`compiled` makes it; the compilations that are needed
    announced together in one line."""
    compiler = shutil.which("gcc") or shutil.which("cc")
    if compiler is None or os.environ.get("SHIPGYM_NO_COMPILE"):
        return list(functions)
    out: list[ca.Function | None] = [None] * len(functions)
    with tempfile.TemporaryDirectory() as tmp:
        todo = []  # (index, source, target) of the libraries not cached yet
        for i, function in enumerate(functions):
            try:
                folder = Path(tmp) / str(i)
                folder.mkdir()
                generator = ca.CodeGenerator(f"{function.name()}.c", {"with_header": False})
                generator.add(function)
                source = Path(generator.generate(str(folder) + os.sep))
                key = hashlib.sha256(source.read_bytes() + " ".join(flags).encode())
                target = cache_dir() / f"{function.name()}_{key.hexdigest()[:20]}.so"
            except (OSError, RuntimeError) as exc:
                out[i] = _fallback(function, exc)
                continue
            if library_problem(target) is None:
                out[i] = _load(function, target)
            else:
                todo.append((i, source, target))
        with _locked(sorted({target for _, _, target in todo})):
            # another process may have published a library while this one waited for it
            todo = _published(functions, todo, out)
            if todo:
                seconds = sum(compile_seconds(source.stat().st_size) for _, source, _ in todo)
                name = what or ", ".join(functions[i].name() for i, _, _ in todo)
                notice(compile_message(name, seconds, cache_dir()))
            for i, source, target in todo:
                out[i] = (
                    _load(functions[i], target)
                    if library_problem(target) is None  # the same library twice in ``functions``
                    else _build(functions[i], compiler, flags, source, target)
                )
    return [f for f in out if f is not None]


def _published(
    functions: Sequence[ca.Function],
    todo: list[tuple[int, Path, Path]],
    out: list[ca.Function | None],
) -> list[tuple[int, Path, Path]]:
    """The entries of ``todo`` whose library is still missing or fails its check; the others
    loaded into ``out``.  A library that is there but fails its check is named in one line
    (:func:`library_problem`): it is compiled again."""
    missing = []
    for i, source, target in todo:
        problem = library_problem(target)
        if problem is None:
            out[i] = _load(functions[i], target)
            continue
        if target.exists():
            notice(f"shipgym: the cached library {target} {problem}: compiling it again")
        missing.append((i, source, target))
    return missing


def record_path(target: Path) -> Path:
    """The sidecar recording the size and SHA-256 of the library ``target``."""
    return target.with_name(f"{target.name}.json")


def file_sha256(file: Path) -> str:
    """The SHA-256 of ``file``'s bytes (hex)."""
    digest = hashlib.sha256()
    with open(file, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


#: libraries this process checked: (path, inode, size, mtime [ns]) of each
_CHECKED: set[tuple[str, int, int, int]] = set()


def library_problem(target: Path) -> str | None:
    """What keeps the library ``target`` from being loaded, in words ("is missing", "is
    3000 bytes, 16480 recorded", "has no record of its size and SHA-256", "differs from
    its recorded SHA-256"), or None when it matches the record written when it was
    compiled (:func:`record_path`)."""
    try:
        info = target.stat()
    except OSError:
        return "is missing"
    stamp = (str(target), info.st_ino, info.st_size, info.st_mtime_ns)
    if stamp in _CHECKED:
        return None
    try:
        record = json.loads(record_path(target).read_text())
        size, sha256 = int(record["size"]), str(record["sha256"])
    except (OSError, ValueError, KeyError, TypeError):
        return "has no record of its size and SHA-256"
    if info.st_size != size:
        return f"is {info.st_size} bytes, {size} recorded"
    try:
        if file_sha256(target) != sha256:
            return "differs from its recorded SHA-256"
    except OSError as exc:
        return f"is unreadable ({exc.strerror})"
    _CHECKED.add(stamp)
    return None


def _write_record(target: Path) -> None:
    """Record the size and SHA-256 of the published library ``target`` beside it,
    atomically."""
    record = {"size": target.stat().st_size, "sha256": file_sha256(target)}
    file = record_path(target)
    staged = file.with_name(f"{file.name}.{os.getpid()}.tmp")
    staged.write_text(json.dumps(record) + "\n")
    os.replace(staged, file)


@contextlib.contextmanager
def _locked(targets: Sequence[Path]) -> Iterator[None]:
    """Exclusive ``fcntl`` locks on ``<target>.lock`` for each of ``targets`` inside, taken
    in the given (sorted) order so that two processes cannot wait for each other; without
    ``fcntl`` (Windows) or a writable folder, no lock (a concurrent compilation then only
    repeats work: the library is published atomically)."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover - not on POSIX
        yield
        return
    with contextlib.ExitStack() as stack:
        for target in targets:
            try:
                target.parent.mkdir(parents=True, exist_ok=True)
                handle = stack.enter_context(open(f"{target}.lock", "a"))
                fcntl.flock(handle.fileno(), fcntl.LOCK_EX)
            except OSError:
                continue
        yield


def _build(
    function: ca.Function, compiler: str, flags: tuple[str, ...], source: Path, target: Path
) -> ca.Function:
    """``function`` compiled from ``source`` into ``target`` and loaded (or itself)."""
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        partial = source.with_name("lib.so")
        subprocess.run(
            [compiler, "-shared", "-fPIC", *flags, str(source), "-o", str(partial)],
            check=True,
            capture_output=True,
        )
        # atomic publish: concurrent processes may compile the same library
        staged = target.with_suffix(f".{os.getpid()}.tmp")
        shutil.copy(partial, staged)
        record_path(target).unlink(missing_ok=True)  # no record of a library being replaced
        os.replace(staged, target)
        _write_record(target)
    except (OSError, subprocess.CalledProcessError, RuntimeError) as exc:
        return _fallback(function, exc)
    return _load(function, target)


def _load(function: ca.Function, target: Path) -> ca.Function:
    try:
        return ca.external(function.name(), str(target))
    except RuntimeError as exc:
        return _fallback(function, exc)


def _fallback(function: ca.Function, exc: Exception) -> ca.Function:
    warnings.warn(f"could not compile {function.name()} ({exc}); using CasADi's VM", stacklevel=4)
    return function

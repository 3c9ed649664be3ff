"""casadi Functions and NLPs compiled to shared libraries with the system C compiler, and
cached: the support MPC's NLPs (the ground station) and a flying vehicle's dynamics.

casadi generates C for a Function, or for the functions a solver evaluates (cost,
constraints and their derivatives); compiled, they run several times faster than casadi's
interpreter (`interpreted_over_compiled_ratio` in `mission bench`). The first use on a
machine generates and compiles (every library at once, one compiler process each); later
ones load the cached libraries and build nothing. Who compiles says so on stderr
(:class:`~mission.codegen.news.Compiling`). Processes that want the same libraries at once
(a ground station and its MPC helper, four vehicles, a study's parallel runs) take turns: one
compiles, the others wait for it and then load what it cached.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import shutil
import subprocess
import tempfile
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import casadi as ca

from mission.codegen.lean_gradient import LEAN, generate_solver_functions, wants_lean_gradient
from mission.codegen.news import Compiling

# -O1: as fast a solve as -O2 (1,220 recorded solves, bit-identical results) and the
# generated ~1.2 MB of C compiles in 5.8 s instead of 8.6 s
COMPILE_FLAGS = ["-O1", "-fPIC", "-shared"]


@dataclass(frozen=True)
class NlpBuild:
    """One NLP to compile: the solver's name and casadi plugin, the NLP (keys x, p, f, g) and
    the solver's options."""

    name: str
    plugin: str
    nlp: dict[str, ca.MX]
    options: dict

    @property
    def part(self) -> str:
        """What it is called when it is compiled."""
        return self.name

    def recipe(self) -> str:
        """What the library is made from (its cache key hashes it)."""
        nlp = self.nlp
        functions = ca.Function("nlp", [nlp["x"], nlp["p"]], [nlp["f"], nlp["g"]])
        options = repr(sorted(self.options.items()))
        lean = [LEAN] if wants_lean_gradient(self.options) else []
        return "\n".join([self.name, self.plugin, options, *lean, functions.serialize()])

    def generate(self, source: str) -> None:
        """Write the C of the functions the solver evaluates to ``source`` (working directory)."""
        solver = ca.nlpsol(self.name, self.plugin, self.nlp, self.options)
        if wants_lean_gradient(self.options):
            generate_solver_functions(solver, self.nlp, self.options, source)
        else:
            solver.generate_dependencies(source)


@dataclass(frozen=True)
class FunctionBuild:
    """One casadi Function to compile (load the library with ``ca.external(function.name(),
    library)``)."""

    function: ca.Function

    @property
    def part(self) -> str:
        """What it is called when it is compiled."""
        return self.function.name()

    def recipe(self) -> str:
        """What the library is made from (its cache key hashes it)."""
        return "\n".join(["function", self.function.serialize()])

    def generate(self, source: str) -> None:
        """Write the function's C to ``source`` (working directory)."""
        self.function.generate(source)


@dataclass(frozen=True)
class KeyedBuild:
    """A build cached under a key from what it is made of (:mod:`mission.codegen.build_key`):
    a cached library loads without its expressions being built; ``make()`` builds them only
    where the library must be compiled."""

    part: str
    key: str
    make: Callable[[], NlpBuild | FunctionBuild]

    def recipe(self) -> str:
        """What the library is made from (its cache key hashes it)."""
        return "\n".join(["keyed", self.part, self.key])

    def generate(self, source: str) -> None:
        """Build the expressions and write their C to ``source`` (working directory)."""
        self.make().generate(source)


Build = NlpBuild | FunctionBuild | KeyedBuild


def compiled_builds(
    builds: list[Build], fallback_dir: Callable[[], str], who: Compiling
) -> list[str | None]:
    """For each build, the functions its casadi solver needs (or the function), compiled into
    a shared library with the system C compiler (about 5x faster plans than interpreting
    them), or None without one. The libraries not yet cached are compiled at the same time,
    one compiler process each.

    A library is cached (under ``$XDG_CACHE_HOME`` or ``~/.cache``) by the hash of the
    serialised NLP, the solver's name, plugin and options, the casadi version, the compiler
    and its flags: a run after the first builds no solver from the expressions, generates no
    C and compiles nothing. A :class:`KeyedBuild` is hashed by its key instead, so a hit does
    not even build the expressions. The C sources are generated in a scratch directory that
    is gone on return; where the cache cannot be written, the libraries go to
    ``fallback_dir()``.
    """
    compiler = c_compiler()
    libraries: list[str | None] = [None] * len(builds)
    if compiler is None:
        return libraries
    names = [_library_name(compiler, build, who.prefix) for build in builds]
    if _take_cached(names, libraries):
        return libraries
    with _turn(who.prefix):  # another process compiling the same waits, then finds them
        if _take_cached(names, libraries):
            return libraries
        missing = {index: name for index, name in enumerate(names) if libraries[index] is None}
        parts = [builds[index].part for index in missing]
        started = time.monotonic()
        who.started(parts, Path(compiler).name, str(_cache_dir()))
        made = _generate_and_compile(compiler, builds, missing, fallback_dir, who.prefix)
        for index, library in made.items():
            libraries[index] = library
        failed = [builds[index].part for index in missing if index not in made]
        done = [builds[index].part for index in missing if index in made]
        if done:
            who.finished(done, time.monotonic() - started)
        if failed:  # interpreted instead: the same results, slower
            who.failed(failed, Path(compiler).name)
    return libraries


def _take_cached(names: list[str], libraries: list[str | None]) -> bool:
    """Fill ``libraries`` with the cached ones of ``names``; whether every one was cached."""
    for index, name in enumerate(names):
        cached = _cache_dir() / name
        if libraries[index] is None and cached.is_file():
            libraries[index] = str(cached)
    return all(library is not None for library in libraries)


@contextlib.contextmanager
def _turn(prefix: str) -> Iterator[None]:
    """This process's turn to compile ``prefix``'s libraries: an exclusive lock on a file in
    the cache (released by the system if the process dies); no lock where the cache cannot be
    written."""
    import fcntl

    try:
        _cache_dir().mkdir(parents=True, exist_ok=True)
        lock = (_cache_dir() / f".{prefix}.lock").open("a")
    except OSError:
        yield
        return
    with lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        yield


def _generate_and_compile(
    compiler: str,
    builds: list[Build],
    missing: dict[int, str],
    fallback_dir: Callable[[], str],
    prefix: str,
) -> dict[int, str]:
    """The C of each missing build generated in a scratch directory, then compiled into the
    cache (or where it cannot be written, ``fallback_dir()``): the libraries made, by index."""
    made: dict[int, str] = {}
    with tempfile.TemporaryDirectory(prefix=f"{prefix}-c-") as scratch:
        sources: dict[int, tuple[str, Path]] = {}
        for index, library_name in missing.items():
            source = f"{prefix}_{index}.c"  # its stem must be a C identifier
            with contextlib.chdir(scratch):  # casadi writes the C file to the working directory
                builds[index].generate(source)
            sources[index] = (library_name, Path(scratch) / source)
        for directory_of in (_cache_dir, lambda: Path(fallback_dir())):
            if not sources:
                break
            try:
                directory = directory_of()
                directory.mkdir(parents=True, exist_ok=True)
            except OSError:
                continue
            for index, library in _compile_all(compiler, sources, directory).items():
                made[index] = library
                del sources[index]
    return made


@contextlib.contextmanager
def compiled_libraries(builds: list[Build], who: Compiling) -> Iterator[list[str | None]]:
    """:func:`compiled_builds` with a private scratch folder for the libraries the cache cannot
    take, gone on leaving: load them inside. Once casadi has loaded a library its file may go
    (no clean-up is left for the exit, which a forked helper makes with os._exit)."""
    with contextlib.ExitStack() as scratch:

        def private_directory() -> str:
            return scratch.enter_context(tempfile.TemporaryDirectory(prefix=f"{who.prefix}-"))

        yield compiled_builds(builds, private_directory, who)


def compiled_function(function: ca.Function, who: Compiling, compiled: bool = True) -> ca.Function:
    """``function`` compiled (and cached) and loaded, or itself, interpreted, without a C
    compiler or when ``compiled`` is False."""
    if not compiled:
        return function
    with compiled_libraries([FunctionBuild(function)], who) as (library,):
        return function if library is None else ca.external(function.name(), library)


def compiled_keyed_function(
    name: str, key: str, make: Callable[[], ca.Function], who: Compiling, compiled: bool = True
) -> ca.Function:
    """The function ``make()`` builds (named ``name``), compiled and cached under ``key``: a
    cached library loads without ``make()`` being called; interpreted (``make()``) without a
    C compiler or when ``compiled`` is False."""
    if not compiled:
        return make()
    build = KeyedBuild(name, key, lambda: FunctionBuild(make()))
    with compiled_libraries([build], who) as (library,):
        return make() if library is None else ca.external(name, library)


def c_compiler() -> str | None:
    """The system C compiler casadi's generated code is compiled with (None: interpreted)."""
    return shutil.which("gcc") or shutil.which("cc")


def _library_name(compiler: str, build: Build, prefix: str) -> str:
    recipe = f"{ca.__version__} {compiler} {' '.join(COMPILE_FLAGS)}\n{build.recipe()}"
    return f"{prefix}_{hashlib.sha256(recipe.encode()).hexdigest()[:16]}.so"


def _compile_all(
    compiler: str, sources: dict[int, tuple[str, Path]], directory: Path
) -> dict[int, str]:
    """Compile every source into ``directory`` at once; the libraries that were made, by
    index. A library appears under its name only when complete."""
    running: dict[int, tuple[subprocess.Popen, Path, Path]] = {}
    made: dict[int, str] = {}
    try:
        for index, (library_name, source) in sources.items():
            partial = directory / f".{library_name}.{os.getpid()}.part"
            command = [compiler, *COMPILE_FLAGS, str(source), "-o", str(partial)]
            with contextlib.suppress(OSError):
                process = subprocess.Popen(
                    command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
                )
                running[index] = (process, partial, directory / library_name)
        for index, (process, partial, library) in running.items():
            try:
                if process.wait() == 0:
                    os.replace(partial, library)
                    made[index] = str(library)
            except OSError:
                pass
            finally:
                partial.unlink(missing_ok=True)
    finally:
        for process, _, _ in running.values():  # interrupted: no compiler outlives us
            if process.poll() is None:
                process.kill()
                process.wait()
    return made


def _cache_dir() -> Path:
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "bridge-uav-formation"

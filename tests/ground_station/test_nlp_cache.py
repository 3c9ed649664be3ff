"""The support MPC's NLPs compiled once with the system C compiler and cached by what they
are: a cache hit builds nothing, anything that changes the generated code is a new library,
and an unwritable cache falls back to a private directory."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from ground_station.support_mpc.nlp import FATROP_OPTIONS
from ground_station.support_mpc.nlp_cache import c_compiler
from tests.extras import require_c_compiler


def _tiny_solver():
    """A two-variable NLP: min (x - p)^2 + (y - 2p)^2 with x + y >= 1, solved by IPOPT."""
    import casadi as ca

    from ground_station.support_mpc.nlp import IPOPT_OPTIONS

    x, p = ca.MX.sym("x", 2), ca.MX.sym("p")
    nlp = {"x": x, "p": p, "f": (x[0] - p) ** 2 + (x[1] - 2 * p) ** 2, "g": x[0] + x[1]}
    return nlp, IPOPT_OPTIONS


def _compiled_nlps(builds, fallback_dir):
    """Each build's library (None without a C compiler), compiled and cached as the support
    MPC's are, into ``fallback_dir()`` where the cache is not writable."""
    from ground_station.support_mpc import nlp_cache
    from mission.codegen import casadi_cache

    return casadi_cache.compiled_builds(builds, fallback_dir, nlp_cache.SUPPORT_MPC)


def _compiled_one(name, plugin, nlp, options, fallback_dir):
    """The library of one NLP, as ``_compiled_nlps`` makes it."""
    from ground_station.support_mpc import nlp_cache

    build = nlp_cache.NlpBuild(name, plugin, nlp, options)
    return _compiled_nlps([build], fallback_dir)[0]


def test_a_compilation_says_so_and_how_long_it_took_and_a_hit_says_nothing(
    tmp_path, monkeypatch, capsys
):
    from ground_station.support_mpc import nlp_cache

    require_c_compiler()
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    nlp, options = _tiny_solver()
    _compiled_one("tiny", "ipopt", nlp, options, lambda: str(tmp_path))
    said = capsys.readouterr().err.splitlines()
    compiler, news = Path(c_compiler()).name, nlp_cache.SUPPORT_MPC
    assert said[0] == f"ground station: {news.starting} (tiny) with {compiler}: " + (
        f"once per machine, cached in {tmp_path / 'cache' / 'bridge-uav-formation'}"
    )
    assert said[1].startswith(f"ground station: {news.done} (tiny) in ") and len(said) == 2
    _compiled_one("tiny", "ipopt", nlp, options, lambda: str(tmp_path))
    assert capsys.readouterr().err == ""


def test_the_compiled_nlp_is_cached_and_a_hit_builds_nothing(tmp_path, monkeypatch):
    import tempfile

    import casadi as ca

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    scratch = tmp_path / "tmp"
    scratch.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(scratch))
    nlp, options = _tiny_solver()

    def no_fallback() -> str:
        raise AssertionError("the cache is writable: no fallback directory")

    first = _compiled_one("tiny", "ipopt", nlp, options, no_fallback)
    if c_compiler() is None:
        assert first is None  # interpreted: nothing to cache
        require_c_compiler()
    assert first is not None and Path(first).parent == tmp_path / "cache" / "bridge-uav-formation"
    assert list(scratch.iterdir()) == []  # the C source's scratch directory is gone
    mtime = Path(first).stat().st_mtime_ns
    interpreted = ca.nlpsol("tiny", "ipopt", nlp, options)

    def no_scratch(*args, **kwargs):
        raise AssertionError("a cache hit generates no C")

    def no_solver(*args, **kwargs):
        raise AssertionError("a cache hit builds no solver from the expressions")

    from mission.codegen import casadi_cache

    with monkeypatch.context() as hit:
        hit.setattr(casadi_cache.tempfile, "TemporaryDirectory", no_scratch)
        hit.setattr(casadi_cache.ca, "nlpsol", no_solver)
        again, _ = _tiny_solver()  # the same NLP, built afresh
        assert _compiled_one("tiny", "ipopt", again, options, no_fallback) == first
    assert Path(first).stat().st_mtime_ns == mtime
    compiled = ca.nlpsol("tiny", "ipopt", first, options)
    expected = interpreted(x0=[0, 0], p=1.5, lbg=1.0, ubg=np.inf)["x"]
    np.testing.assert_allclose(compiled(x0=[0, 0], p=1.5, lbg=1.0)["x"], expected, atol=1e-9)
    np.testing.assert_allclose(expected, [[1.5], [3.0]], atol=1e-4)  # IPOPT tol 1e-4
    # Anything that changes the generated functions is a different library.
    exact_only = {k: v for k, v in options.items() if k != "calc_lam_p"}
    changed = {**nlp, "f": nlp["f"] + nlp["x"][0]}
    others = [
        _compiled_one("tiny", "ipopt", changed, options, no_fallback),
        _compiled_one("tiny", "ipopt", nlp, exact_only, no_fallback),
        _compiled_one("other", "ipopt", nlp, options, no_fallback),
    ]
    assert len({first, *others}) == 4
    # Another plugin needs its own functions (fatrop's Lagrangian Hessian has other outputs).
    plain = {"print_time": False}
    by_plugin = {
        plugin: _compiled_one("tiny", plugin, nlp, plain, no_fallback)
        for plugin in ("ipopt", "fatrop")
    }
    assert by_plugin["ipopt"] != by_plugin["fatrop"]
    fatrop = ca.nlpsol("tiny", "fatrop", by_plugin["fatrop"], FATROP_OPTIONS)
    solved = fatrop(x0=[0, 0], p=1.5, lbg=1.0, ubg=10.0)["x"]  # fatrop: finite bounds only
    np.testing.assert_allclose(solved, expected, atol=1e-4)


def test_several_nlps_compile_at_once_and_only_the_missing_ones(tmp_path, monkeypatch):
    import subprocess

    import casadi as ca

    from ground_station.support_mpc import nlp_cache
    from mission.codegen import casadi_cache

    require_c_compiler()
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    nlp, options = _tiny_solver()
    shifted = {**nlp, "f": nlp["f"] + nlp["x"][1]}
    scaled = {**nlp, "f": 2 * nlp["f"]}
    launched: list[subprocess.Popen] = []
    popen = subprocess.Popen

    def counting(*args, **kwargs):
        launched.append(popen(*args, **kwargs))
        return launched[-1]

    monkeypatch.setattr(casadi_cache.subprocess, "Popen", counting)

    def builds(*nlps):
        return [nlp_cache.NlpBuild("tiny", "ipopt", n, options) for n in nlps]

    def no_fallback() -> str:
        raise AssertionError("the cache is writable: no fallback directory")

    first = _compiled_nlps(builds(nlp, shifted), no_fallback)
    assert len(launched) == 2 and all(p.returncode == 0 for p in launched)
    assert None not in first and len(set(first)) == 2
    again = _compiled_nlps(builds(nlp, scaled, shifted), no_fallback)
    assert len(launched) == 3  # only the new one compiled
    assert (again[0], again[2]) == (first[0], first[1]) and again[1] not in first
    cache = tmp_path / "cache" / "bridge-uav-formation"
    libraries = sorted(path.name for path in cache.iterdir() if path.suffix == ".so")
    assert libraries == sorted(Path(f).name for f in again)
    solved = ca.nlpsol("tiny", "ipopt", again[1], options)(x0=[0, 0], p=1.5, lbg=1.0)["x"]
    np.testing.assert_allclose(solved, [[1.5], [3.0]], atol=1e-4)  # 2x the cost: same optimum


def test_an_unwritable_cache_compiles_into_the_fallback_directory(tmp_path, monkeypatch):
    import casadi as ca

    blocker = tmp_path / "not-a-directory"
    blocker.write_text("")
    monkeypatch.setenv("XDG_CACHE_HOME", str(blocker))
    fallback = tmp_path / "private"
    nlp, options = _tiny_solver()
    library = _compiled_one("tiny", "ipopt", nlp, options, lambda: str(fallback))
    if c_compiler() is None:
        assert library is None  # interpreted: nothing to cache
        require_c_compiler()
    assert library is not None and Path(library).parent == fallback
    solved = ca.nlpsol("tiny", "ipopt", library, options)(x0=[0, 0], p=-1.0, lbg=1.0)["x"]
    # (x - p, y - 2p) projected onto x + y >= 1 from (-1, -2): the constraint is active
    np.testing.assert_allclose(solved, [[1.0], [0.0]], atol=1e-4)


TINY_COMPILE = """
import casadi as ca
from ground_station.support_mpc import nlp_cache
from ground_station.support_mpc.nlp import IPOPT_OPTIONS

x, p = ca.MX.sym("x", 2), ca.MX.sym("p")
nlp = {"x": x, "p": p, "f": (x[0] - p) ** 2 + (x[1] - 2 * p) ** 2, "g": x[0] + x[1]}
with nlp_cache.compiled_libraries([nlp_cache.NlpBuild("tiny", "ipopt", nlp, IPOPT_OPTIONS)]) as (
    library,
):
    print(library)
"""


@pytest.mark.slow
def test_processes_wanting_the_same_library_at_once_compile_it_once(tmp_path):
    """A ground station and its helper (or four vehicles) start together on a fresh machine:
    one compiles, the others wait for it and load what it cached."""
    import fcntl
    import os
    import subprocess
    import sys

    require_c_compiler()
    env = {**os.environ, "XDG_CACHE_HOME": str(tmp_path / "cache")}
    cache = tmp_path / "cache" / "bridge-uav-formation"
    cache.mkdir(parents=True)
    with (cache / ".support_mpc.lock").open("a") as held:  # the turn is taken: all three wait
        fcntl.flock(held, fcntl.LOCK_EX)
        processes = [
            subprocess.Popen(
                [sys.executable, "-c", TINY_COMPILE],
                env=env,
                stdout=subprocess.PIPE,
                stderr=subprocess.PIPE,
                text=True,
            )
            for _ in range(3)
        ]
        waiting = _waiting_on_locks({process.pid for process in processes}, timeout_s=60.0)
        assert waiting == {process.pid for process in processes}, "each waits for its turn"
        assert not list(cache.glob("*.so"))
    outputs = [process.communicate(timeout=120) for process in processes]
    assert all(process.returncode == 0 for process in processes), outputs
    libraries = {out.strip() for out, _ in outputs}
    assert len(libraries) == 1 and libraries.pop().startswith(str(tmp_path / "cache"))
    said = "".join(err for _, err in outputs).splitlines()
    assert [line.split(" with ")[0] for line in said if "compiling" in line] == [
        "ground station: compiling the support MPC (tiny)"
    ]
    assert len([line for line in said if "compiled the support MPC (tiny) in" in line]) == 1


def test_a_failed_compilation_says_so_and_the_nlp_is_interpreted(tmp_path, monkeypatch, capsys):
    from mission.codegen import casadi_cache
    from mission.runs.compile_relay import CompileRelay, compile_summary

    require_c_compiler()
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    monkeypatch.setattr(casadi_cache, "COMPILE_FLAGS", ["--no-such-flag", "-shared"])
    nlp, options = _tiny_solver()
    assert _compiled_one("tiny", "ipopt", nlp, options, lambda: str(tmp_path)) is None
    said = capsys.readouterr().err
    assert "could not compile the support MPC (tiny) with" in said
    assert "compiled the support MPC" not in said  # nothing said done that was not
    log = tmp_path / "ground_station.log"
    log.write_text(said)
    relay = CompileRelay(log)
    relay.poll()
    assert not relay.compiling and compile_summary(log) == {}  # no compile to leave out


def _waiting_on_locks(pids: set[int], timeout_s: float) -> set[int]:
    """Which of ``pids`` wait on a file lock (Linux's /proc/locks lists a blocked request
    as ``-> FLOCK ...``), once all do or the time is up."""
    import time

    deadline = time.monotonic() + timeout_s
    while True:
        blocked = set()
        for line in Path("/proc/locks").read_text().splitlines():
            fields = line.split()
            if "->" in fields and "FLOCK" in fields:
                blocked.add(int(fields[fields.index("->") + 4]))
        if pids <= blocked or time.monotonic() > deadline:
            return blocked & pids
        time.sleep(0.1)

"""A compiled solver's ``nlp_grad`` without the gradients casadi throws away: the same
solutions bit for bit as the functions casadi generates itself, a different cache key, and
the full set where a solver asks for the parameters' multipliers."""

from __future__ import annotations

import casadi as ca
import numpy as np

from ground_station.support_mpc.nlp import FATROP_OPTIONS, IPOPT_OPTIONS
from mission.codegen.casadi_cache import NlpBuild
from mission.codegen.lean_gradient import LEAN, lean_gradient
from mission.codegen.news import Compiling
from tests.extras import require_c_compiler

N_VALUES = 400


def _gathering_nlp():
    """Three variables drawn to a point and to a table of parameter values gathered at an
    index that moves with x (as the support MPC gathers G's voxels), one constraint."""
    x = ca.MX.sym("x", 3)
    p = ca.MX.sym("p", 3 + N_VALUES)
    index = ca.fmin(ca.fmax(ca.floor(10 * (x[0] + 2)), 0), N_VALUES - 1)
    f = ca.sumsqr(x - p[:3]) + p[3 + index] * x[1] ** 2 + 0.1 * x[2] ** 4
    return {"x": x, "p": p, "f": f, "g": ca.vertcat(x[0] + x[1], ca.sumsqr(x))}


def _solver(nlp, options, tmp_path, lean: bool, name: str):
    """The NLP's solver from a library of casadi's own functions or of the lean ones."""
    from mission.codegen import casadi_cache

    opts = dict(options) if lean else {**options, "calc_lam_p": True}
    build = NlpBuild(name, "fatrop", nlp, opts)
    (library,) = casadi_cache.compiled_builds(
        [build], lambda: str(tmp_path), Compiling("test", "a test NLP", "test_lean")
    )
    assert library is not None
    return ca.nlpsol(name, "fatrop", library, opts)


def test_the_lean_library_solves_bit_for_bit_as_casadis_own(tmp_path, monkeypatch):
    require_c_compiler()
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    nlp = _gathering_nlp()
    own = _solver(nlp, FATROP_OPTIONS, tmp_path, lean=False, name="own")
    lean = _solver(nlp, FATROP_OPTIONS, tmp_path, lean=True, name="lean")
    rng = np.random.default_rng(3)
    for _ in range(20):
        p = np.concatenate([rng.uniform(-1, 1, 3), rng.uniform(0.1, 2, N_VALUES)])
        x0 = rng.uniform(-1, 1, 3)
        ubg = [1.0, 4.0]
        a = own(x0=x0, p=p, lbg=-np.inf, ubg=ubg)
        b = lean(x0=x0, p=p, lbg=-np.inf, ubg=ubg)
        for key in ("x", "f", "g", "lam_g"):
            assert np.array_equal(np.asarray(a[key]), np.asarray(b[key])), key
        assert own.stats()["unified_return_status"] == lean.stats()["unified_return_status"]
        assert own.stats()["iter_count"] == lean.stats()["iter_count"]


def test_the_lean_gradient_gives_casadis_f_and_g_and_no_unused_gradient():
    nlp = _gathering_nlp()
    own = ca.nlpsol("own", "fatrop", nlp, FATROP_OPTIONS).get_function("nlp_grad")
    lean = lean_gradient(nlp, with_x=False)
    with_x = lean_gradient(nlp, with_x=True)
    assert lean.name_in() == own.name_in() and lean.name_out() == own.name_out()
    assert lean.nnz_out(2) == 0 and lean.nnz_out(3) == 0  # nothing left of either gradient
    rng = np.random.default_rng(4)
    for _ in range(10):
        args = [rng.uniform(-1, 1, 3), rng.uniform(0.1, 2, 3 + N_VALUES), 1.0, [0.3, -0.2]]
        expected, got, full = own(*args), lean(*args), with_x(*args)
        assert float(got[0]) == float(expected[0])
        assert np.array_equal(np.asarray(got[1]), np.asarray(expected[1]))
        np.testing.assert_allclose(np.asarray(full[2]), np.asarray(expected[2]), rtol=1e-12)


def test_a_lean_library_has_its_own_cache_key_and_only_without_lam_p():
    nlp = _gathering_nlp()
    lean = NlpBuild("n", "fatrop", nlp, FATROP_OPTIONS)
    full = NlpBuild("n", "fatrop", nlp, {**FATROP_OPTIONS, "calc_lam_p": True})
    assert LEAN in lean.recipe().splitlines()
    assert LEAN not in full.recipe().splitlines()
    assert LEAN not in NlpBuild("n", "ipopt", nlp, {**IPOPT_OPTIONS, "calc_lam_p": True}).recipe()

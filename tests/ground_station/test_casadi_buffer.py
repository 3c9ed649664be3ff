"""A casadi Function called on arrays it owns: the same values as casadi's own call, inputs
kept between calls, and a solver's failure told apart from an error without its stats."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from mission.codegen.casadi_buffer import BufferedFunction

OPTIONS = {
    "structure_detection": "none",
    "print_time": False,
    "error_on_fail": True,
    "fatrop": {"print_level": 0, "max_iter": 50},
}


def _solver(options=OPTIONS):
    """min (x - p)^2 + (y - 2p)^2 subject to x + y <= ubg."""
    x, p = ca.MX.sym("x", 2), ca.MX.sym("p")
    nlp = {"x": x, "p": p, "f": (x[0] - p) ** 2 + (x[1] - 2 * p) ** 2, "g": x[0] + x[1]}
    solver = ca.nlpsol("s", "fatrop", nlp, options)
    return solver, BufferedFunction(
        solver, ("x", "f"), {"lbx": -np.inf, "ubx": np.inf, "lbg": -np.inf}
    )


def test_a_call_gives_casadis_values_and_unnamed_inputs_keep_theirs():
    solver, buffered = _solver()
    first = buffered(x0=[0.0, 0.0], p=1.0, ubg=1.0)
    expected = solver(x0=[0, 0], p=1.0, lbg=-np.inf, ubg=1.0)
    assert np.array_equal(first["x"], np.asarray(expected["x"]).ravel())
    again = buffered(x0=[0.5, 0.5])  # p and ubg as before
    np.testing.assert_allclose(again["x"], first["x"], atol=1e-6)


def test_a_converged_solve_says_so_without_stats():
    _, buffered = _solver()
    outputs, succeeded = buffered.solve(x0=[0.0, 0.0], p=1.0, ubg=1.0)
    assert succeeded
    np.testing.assert_allclose(outputs["x"], [0.0, 1.0], atol=1e-6)  # on x + y = 1
    assert buffered.stats()["unified_return_status"] == "SOLVER_RET_SUCCESS"


def test_a_failed_solve_returns_where_it_stopped_and_false():
    _, buffered = _solver({**OPTIONS, "fatrop": {"print_level": 0, "max_iter": 1}})
    outputs, succeeded = buffered.solve(x0=[5.0, -7.0], p=3.0, ubg=1.0)
    assert not succeeded
    assert np.all(np.isfinite(outputs["x"])) and not np.allclose(outputs["x"], [5.0, -7.0])
    assert buffered.stats()["unified_return_status"] != "SOLVER_RET_SUCCESS"


def test_an_error_that_is_not_a_failed_solve_is_raised():
    _, buffered = _solver({**OPTIONS, "fatrop": {"print_level": 0, "no_such_option": 1}})
    with pytest.raises(RuntimeError, match="no_such_option"):
        buffered.solve(x0=[0.0, 0.0], p=1.0, ubg=1.0)


def test_an_exception_inside_the_solver_is_raised_not_taken_for_a_failed_solve(monkeypatch):
    _, buffered = _solver()
    failed = "nlpsol process failed. Set 'error_on_fail' option to false to ignore this error."

    def breaks():
        raise RuntimeError(failed)

    monkeypatch.setattr(buffered, "_evaluate", breaks)
    for status, raised in (("SOLVER_RET_EXCEPTION", True), ("SOLVER_RET_LIMITED", False)):
        monkeypatch.setattr(
            buffered, "stats", lambda status=status: {"unified_return_status": status}
        )
        if raised:
            with pytest.raises(RuntimeError, match="error_on_fail"):
                buffered.solve(x0=[0.0, 0.0], p=1.0, ubg=1.0)
        else:
            assert buffered.solve(x0=[0.0, 0.0], p=1.0, ubg=1.0)[1] is False

"""Sharing the support MPCs with a helper process: the same plans, shared longest first, and a
dead helper's share solved here."""

from __future__ import annotations

import os
import sys
from dataclasses import replace

import numpy as np
import pytest

from ground_station.control.work_mpc import predict_work
from ground_station.support_mpc.branches import CONVERGED
from ground_station.support_mpc.mpc import PlanRequest, SupportMpc, SupportPlan
from ground_station.support_mpc.sharing import HelperPlanner, LocalPlanner, MpcHelper
from mission.link.plan_files import read_plan


@pytest.fixture(scope="module")
def local(along_world) -> LocalPlanner:
    scenario = along_world.scenario
    mpc = SupportMpc(
        scenario.control,
        along_world.map_grid(),
        along_world.camera,
        along_world.sigma0_map().sigma_m,
    )
    return LocalPlanner(mpc, along_world.camera.observable)


def _requests(world, mpc: SupportMpc, index: int) -> list[PlanRequest]:
    """The three supports' problems with the work UAV at waypoint ``index`` (raised G)."""
    control = world.scenario.control
    plan = read_plan(world.scenario)
    work = predict_work(
        plan.work[index], index + 1, plan.work, control.horizon_steps, control.d_max_work_m, 0.1
    )
    g = world.sigma0_map().sigma_m.copy()
    g[20:26, 10:30, 5:12] += 1.5  # a worse-than-predicted region for the escape starts
    offset = np.array([0.4, -0.3, 0.2])
    return [
        mpc.request(
            f"support-{n + 1}",
            plan.supports[n][index] + offset,
            plan.supports[n],
            work.path,
            work.indices,
            g,
            escape=n == 0,
        )
        for n in range(len(plan.supports))
    ]


def _same(a: SupportPlan, b: SupportPlan) -> bool:
    return (
        np.array_equal(a.path, b.path)
        and a.status == b.status
        and np.array_equal(a.blocked, b.blocked)
        and a.resolved == b.resolved
        and np.array_equal(a.anchors, b.anchors)
    )


@pytest.mark.slow
def test_the_helper_makes_the_same_plans_bit_for_bit_and_stops_when_closed(along_world, local):
    helper = MpcHelper()
    helper.set_up(along_world.scenario, along_world.sigma0_map().sigma_m)
    shared = HelperPlanner(local.mpc, local.observable, helper)
    try:
        for index in (2, 6, 9):
            requests = _requests(along_world, local.mpc, index)
            expected = local.plan_all(requests)
            got = shared.plan_all(requests)
            assert list(got) == [r.name for r in requests]
            assert all(_same(got[name], expected[name]) for name in expected)
        assert shared.helper is not None  # it was used throughout, not dropped
    finally:
        shared.close()
    assert helper.process.returncode == 0


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="needs /proc")
def test_a_plan_does_not_depend_on_the_solves_before_it(along_world, local):
    """The helper's bit-for-bit promise needs solves without memory: the same problems
    planned in the opposite order give the same plans, bit for bit. (fatrop fed an infinite
    constraint bound carried its failure into later solves; no bound is infinite now.)"""
    requests = [r for index in (2, 6, 9) for r in _requests(along_world, local.mpc, index)]
    requests += [  # out of reach of the terminal waypoint: the far branch alone
        replace(r, yhat=r.yhat + [7.0, 0.0, 0.0]) for r in _requests(along_world, local.mpc, 4)
    ]
    forward = [local.mpc.plan(r, local.observable) for r in requests]
    backward = [local.mpc.plan(r, local.observable) for r in reversed(requests)][::-1]
    assert all(_same(a, b) for a, b in zip(forward, backward, strict=True))
    assert sum(plan.status == CONVERGED for plan in forward) == len(requests)
    assert all(np.isfinite(bounds).all() for bounds in local.mpc.branches.upper_bounds.values())


@pytest.mark.parametrize("solver", ["ipopt", "fatrop"])
def test_an_interpreted_mpc_plans_as_the_compiled_one(along_world, local, monkeypatch, solver):
    """Without a C compiler the NLP is interpreted; with ``mpc_solver: ipopt`` IPOPT
    solves it. Either way the plans are the compiled fatrop's: fatrop runs
    IPOPT's algorithm, and the interpreter evaluates the same functions."""
    from dataclasses import replace as replaced

    from mission.codegen import casadi_cache

    def no_compiling(*_):
        raise AssertionError("compiled=False compiles nothing")

    monkeypatch.setattr(casadi_cache, "compiled_builds", no_compiling)  # the margins' too
    control = replaced(along_world.scenario.control, mpc_solver=solver)
    sigma0 = along_world.sigma0_map().sigma_m
    interpreted = SupportMpc(
        control, along_world.map_grid(), along_world.camera, sigma0, compiled=False
    )
    requests = [r for index in (2, 6, 9) for r in _requests(along_world, local.mpc, index)]
    for request in requests:
        ours = local.mpc.plan(request, local.observable)
        theirs = interpreted.plan(request, local.observable)
        assert (ours.status, theirs.status) == (CONVERGED, CONVERGED)
        # the two solvers stop at tolerance 1e-4: ~1 mm apart where a margin is active
        np.testing.assert_allclose(theirs.path, ours.path, atol=2e-3 if solver == "ipopt" else 1e-6)


@pytest.mark.slow
def test_the_helper_asks_blas_for_one_thread_unless_told(along_world, local, monkeypatch):
    def threads_after_a_plan() -> int:
        helper = MpcHelper(fork=False)  # a fresh interpreter: its BLAS reads the environment
        helper.set_up(along_world.scenario, along_world.sigma0_map().sigma_m)
        shared = HelperPlanner(local.mpc, local.observable, helper)
        try:
            shared.plan_all(_requests(along_world, local.mpc, 2))  # numpy, casadi in
            return len(os.listdir(f"/proc/{helper.process.pid}/task"))
        finally:
            shared.close()

    monkeypatch.delenv("OPENBLAS_NUM_THREADS", raising=False)
    unset = threads_after_a_plan()
    monkeypatch.setenv("OPENBLAS_NUM_THREADS", "1")
    assert unset == threads_after_a_plan()  # (Embree may have a worker of its own)
    if (os.cpu_count() or 1) >= 2:
        monkeypatch.setenv("OPENBLAS_NUM_THREADS", "2")
        assert threads_after_a_plan() > unset  # numpy's and casadi's OpenBLAS add workers


@pytest.mark.slow
def test_setting_up_a_dead_helper_fails_with_an_os_error(along_world):
    helper = MpcHelper()
    helper.process.kill()
    helper.process.wait()
    with pytest.raises(OSError):  # the station then solves everything itself
        helper.set_up(along_world.scenario, along_world.sigma0_map().sigma_m)
    helper.close()


@pytest.mark.slow
def test_a_dead_helpers_share_is_solved_here(along_world, local, capfd):
    helper = MpcHelper()
    helper.set_up(along_world.scenario, along_world.sigma0_map().sigma_m)
    shared = HelperPlanner(local.mpc, local.observable, helper)
    requests = _requests(along_world, local.mpc, 4)
    shared.plan_all(requests)  # the helper answered once
    helper.process.kill()
    helper.process.wait()
    got = shared.plan_all(requests)
    expected = local.plan_all(requests)
    assert all(_same(got[name], expected[name]) for name in expected)
    assert shared.helper is None
    assert "MPC helper stopped" in capfd.readouterr().err
    shared.plan_all(requests)  # and it goes on without one
    shared.close()


def test_the_longest_expected_solve_goes_to_the_helper_the_rest_balance(local):
    shared = HelperPlanner(local.mpc, local.observable, helper=None)  # type: ignore[arg-type]
    shared.helper = object()  # a stand-in: only the sharing is under test

    def share(*names: str) -> tuple[list[str], list[str]]:
        return shared._share(names)

    assert share("a", "b", "c") == (["a"], ["b", "c"])  # no history: the first goes out
    assert share("a") == ([], ["a"])  # one solve: no round trip
    shared._expected_ms = {"a": 2.0, "b": 9.0, "c": 3.0}
    assert share("a", "b", "c") == (["b"], ["c", "a"])
    shared._expected_ms = {"a": 4.0, "b": 4.0, "c": 3.0, "d": 3.0}
    assert share("a", "b", "c", "d") == (["a", "d"], ["b", "c"])  # 7 ms each
    shared.helper = None
    assert share("a", "b") == ([], ["a", "b"])


def test_the_helpers_share_is_sent_before_this_process_solves_its_own(along_world, local):
    requests = _requests(along_world, local.mpc, 6)
    events: list[str] = []

    class RecordingHelper:  # answers with the plans this process would make
        def send(self, batch):
            events.append("send " + ",".join(r.name for r in batch))
            self.answer = [local.mpc.plan(r, local.observable) for r in batch]

        def receive(self):
            events.append("receive")
            return self.answer

    class RecordingMpc:  # this process's solves, recorded
        def plan(self, request, observable):
            events.append("solve " + request.name)
            return local.mpc.plan(request, observable)

    shared = HelperPlanner(RecordingMpc(), local.observable, helper=RecordingHelper())  # type: ignore[arg-type]
    shared._expected_ms = {"support-1": 1.0, "support-2": 9.0, "support-3": 2.0}
    plans = shared.plan_all(requests)
    assert events == ["send support-2", "solve support-3", "solve support-1", "receive"]
    assert list(plans) == ["support-1", "support-2", "support-3"]  # in the order asked
    expected = local.plan_all(requests)
    assert all(_same(plans[name], expected[name]) for name in expected)

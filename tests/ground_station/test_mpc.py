"""Work MPC (Algorithm 1) by hand; support MPC behaviour with G unchanged and raised."""

from __future__ import annotations

import numpy as np
import pytest

from ground_station.control.work_mpc import predict_work
from ground_station.estimation.gnss_map import LocalizabilityMap, hermite_zero_slope
from ground_station.support_mpc.branches import CONVERGED
from ground_station.support_mpc.mpc import SupportMpc
from mission.link.plan_files import read_plan
from tests.extras import require_c_compiler


def test_work_mpc_steps_greedily_and_advances_the_index():
    waypoints = np.array([[0.0, 0, 0], [1.0, 0, 0], [1.0, 0.5, 0]])
    prediction = predict_work(
        np.array([0.0, 0, 0]), 1, waypoints, horizon=5, d_max_m=0.3, arrival_tol_m=0.1
    )
    expected = [[0.3, 0, 0], [0.6, 0, 0], [0.9, 0, 0], [1.0, 0, 0], [1.0, 0.3, 0], [1.0, 0.5, 0]]
    np.testing.assert_allclose(prediction.path, expected, atol=1e-12)
    # k is recorded before the arrival check: step 4 arrives at w_1, so step 5 targets w_2.
    assert prediction.indices.tolist() == [1, 1, 1, 1, 2, 2]
    np.testing.assert_allclose(prediction.command, [0.3, 0, 0])


def test_work_mpc_stays_on_the_last_waypoint():
    waypoints = np.array([[0.0, 0, 0], [0.05, 0, 0]])
    prediction = predict_work(np.zeros(3), 1, waypoints, 3, 0.3, 0.1)
    assert prediction.indices.tolist() == [1, 1, 1, 1]
    np.testing.assert_allclose(prediction.path[-1], waypoints[1])


@pytest.fixture(scope="module")
def setting(along_world):
    scenario = along_world.scenario
    plan = read_plan(scenario)
    grid = along_world.map_grid()
    mpc = SupportMpc(scenario.control, grid, along_world.camera)
    return along_world, plan, grid, mpc


def _run(setting, adaptive_raise: bool, cycles: int = 12):
    world, plan, grid, mpc = setting
    scenario = world.scenario
    g = LocalizabilityMap(grid, world.sigma0_map().sigma_m, scenario.map, adaptive=True)
    yhat = plan.supports[0][5].copy()  # w_1,6, the Wall scenario's waypoint
    raised = None
    if adaptive_raise:
        centre = grid.index_of(yhat[None])[0]
        lo, hi = np.maximum(centre - 1, 0), centre + 2
        g.values[lo[0] : hi[0], lo[1] : hi[1], lo[2] : hi[2]] = 2.0
        raised = (grid.origin_m + lo * grid.voxel_m, grid.origin_m + hi * grid.voxel_m)
    xhat, k = plan.work[5].copy(), 5
    warm, positions, steps = None, [], []
    for _ in range(cycles):
        work = predict_work(
            xhat,
            k,
            plan.work,
            scenario.control.horizon_steps,
            scenario.control.d_max_work_m,
            scenario.control.arrival_tol_m,
        )
        escape = bool(g.smoothed(yhat)[0] > hermite_zero_slope(g.initial, grid, yhat)[0] + 0.05)
        result = mpc.solve(
            yhat,
            plan.supports[0],
            work.path,
            work.indices,
            g.values,
            world.camera.observable,
            warm,
            escape=escape,
        )
        steps.append(np.linalg.norm(np.diff(np.vstack([yhat, result.path]), axis=0), axis=1))
        warm = result.path
        move = result.command - yhat
        reach = scenario.control.s_max_support_m_s * scenario.control.t_cont_s
        yhat = yhat + move * min(1.0, reach / max(np.linalg.norm(move), 1e-12))
        positions.append(yhat.copy())
    return np.array(positions), raised, np.concatenate(steps), plan.supports[0][5]


def test_with_g_unchanged_the_plan_follows_the_pre_planned_path(setting):
    positions, _, steps, waypoint = _run(setting, adaptive_raise=False)
    # The relative term pulls a little toward the work UAV; it stays near its waypoint.
    assert np.max(np.linalg.norm(positions - waypoint, axis=1)) < 1.0
    assert np.all(steps <= setting[0].scenario.control.d_max_support_m + 0.05)


def test_with_g_raised_around_the_uav_the_plan_leaves_the_region(setting):
    positions, (lo, hi), steps, _ = _run(setting, adaptive_raise=True)
    inside = np.all((positions >= lo) & (positions <= hi), axis=1)
    assert not inside[3:].any(), f"still inside after 3 cycles: {inside}"
    assert np.all(steps <= setting[0].scenario.control.d_max_support_m + 0.05)


@pytest.mark.parametrize(
    "offset",
    [(0.3, -0.2, 0.1), (-7.0, 0.0, 0.0)],
    ids=["terminal-in-reach", "terminal-out-of-reach"],
)
def test_casadi_optimum_matches_scipy_on_the_numpy_cost(setting, offset):
    """The casadi model equals an independent numpy cost (xi with its jump at d_max); SLSQP
    finds the same optimum, whether it ends within d_max of the terminal waypoint (the near
    branch) or, with the terminal out of reach, beyond it (the far branch)."""
    from scipy.optimize import minimize

    from ground_station.support_mpc.cost_check import support_cost_numpy

    world, plan, grid, mpc = setting
    control = world.scenario.control
    g = world.sigma0_map().sigma_m
    yhat = plan.supports[0][3] + np.array(offset)
    work = predict_work(plan.work[3], 4, plan.work, 5, control.d_max_work_m, control.arrival_tol_m)
    result = mpc.solve(yhat, plan.supports[0], work.path, work.indices, g, world.camera.observable)
    targets, terminal = plan.supports[0][work.indices[:5]], plan.supports[0][work.indices[5]]
    out_of_reach = np.linalg.norm(terminal - yhat) > 6 * control.d_max_support_m
    ends_far = np.linalg.norm(terminal - result.path[-1]) > control.d_max_support_m
    assert ends_far == out_of_reach

    def cost(x):
        return support_cost_numpy(
            x,
            yhat,
            targets,
            terminal,
            work.path[:5],
            result.blocked,
            g,
            grid,
            control,
            result.anchors,
        )

    def steps_left(x):
        v = x.reshape(-1, 3)
        steps = np.vstack([v[0] - yhat, np.diff(v, axis=0)])
        return control.d_max_support_m**2 - np.sum(steps**2, axis=1)

    # A feasible start: even fractions of the way to the terminal, at most d_max a step.
    distance = np.linalg.norm(terminal - yhat)
    fraction = min(1 / 6, control.d_max_support_m / distance)
    start = (yhat + (terminal - yhat) * fraction * np.arange(1, 6)[:, None]).ravel()
    reference = minimize(
        cost,
        start,
        method="SLSQP",
        options={"maxiter": 300, "ftol": 1e-12},
        constraints=[{"type": "ineq", "fun": steps_left}],
    )
    # Status 8: SLSQP found no descent direction at its finite-difference precision (far
    # from the terminal the w_penalty term makes the cost ~500); the point is still checked.
    assert reference.success or reference.status == 8, reference.message
    np.testing.assert_allclose(reference.x.reshape(-1, 3), result.path, atol=0.01)
    ours = cost(result.path.ravel())
    assert ours == pytest.approx(reference.fun, rel=1e-5)
    assert ours <= reference.fun * (1 + 1e-7)  # our optimum is at least as good


def test_the_far_branch_is_skipped_only_where_it_cannot_win(setting, monkeypatch):
    """Far is not solved when near converged below far's floor (w_penalty d_max^2 + w_GNSS U
    min G); solving it anyway never finds a cheaper plan, so the skip keeps the exact xi."""
    world, plan, _, mpc = setting
    control = world.scenario.control
    g = world.sigma0_map().sigma_m
    work = predict_work(plan.work[3], 4, plan.work, 5, control.d_max_work_m, control.arrival_tol_m)
    calls = []
    solve_branch = mpc.branches._solve_branch

    def spy(fixed, flags, guess, branch):
        result = solve_branch(fixed, flags, guess, branch)
        calls.append((branch, (fixed, flags, guess), result))
        return result

    monkeypatch.setattr(mpc.branches, "_solve_branch", spy)
    terminal = plan.supports[0][work.indices[5]]
    away = np.array([1.0, 0.0, 0.0]) * control.d_max_support_m
    starts = [plan.supports[0][3] + o for o in np.random.default_rng(5).uniform(-2, 2, (6, 3))]
    starts += [terminal + k * away for k in (4.5, 5.0, 5.5, 5.9)]  # in reach, near stretched
    for yhat in starts:
        mpc.solve(yhat, plan.supports[0], work.path, work.indices, g, world.camera.observable)
    skipped = [
        (arguments, result)
        for i, (branch, arguments, result) in enumerate(calls)
        if branch == "near" and (i + 1 == len(calls) or calls[i + 1][0] != "far")
    ]
    assert len(skipped) >= 6  # near wins by far's floor around the waypoint
    for arguments, near in skipped:
        far = solve_branch(*arguments, "far")
        assert far[2] >= near[2] - 1e-9


def test_the_far_branch_is_solved_where_it_wins(setting):
    """A blocked last step anchored 4 m beyond the terminal waypoint: near must end within
    d_max of the terminal and pays the LOS penalty; far's plan, beyond d_max, is cheaper."""
    world, plan, _, mpc = setting
    horizon, d_max = mpc.horizon, world.scenario.control.d_max_support_m
    yhat = plan.supports[0][3]
    targets = np.repeat(yhat[None], horizon, axis=0)
    terminal = yhat + np.array([d_max, 0.0, 0.0])
    work = np.repeat((yhat + [0.0, 0.0, 3.0])[None], horizon, axis=0)
    anchors = work.copy()
    anchors[-1] = terminal + [0.0, 4.0, 0.0]
    blocked = np.zeros(horizon)
    blocked[-1] = 1.0
    corner, window = mpc.window_of(yhat, world.sigma0_map().sigma_m)
    fixed = np.concatenate([yhat, targets.ravel(), terminal, work.ravel()])
    guess = np.linspace(yhat, terminal, horizon + 1)[1:]
    margins = mpc.margins.parameters(guess, yhat, np.zeros((0, horizon, 3)))
    flags = np.concatenate([anchors.ravel(), blocked, corner, window, margins])
    path, status, cost = mpc.branches.solve(fixed, flags, guess)
    near = mpc.branches._solve_branch(fixed, flags, guess, "near")
    assert status == CONVERGED
    assert np.linalg.norm(path[-1] - terminal) > d_max
    assert cost < near[2]
    assert cost == pytest.approx(mpc.branches.cost(fixed, flags, path))


def test_building_the_mpc_leaves_no_files_in_the_working_directory(
    along_world, tmp_path, monkeypatch
):
    monkeypatch.chdir(tmp_path)
    mpc = SupportMpc(along_world.scenario.control, along_world.map_grid(), along_world.camera)
    assert mpc.horizon == 5
    assert list(tmp_path.iterdir()) == []


def test_an_mpc_compiled_outside_the_cache_leaves_no_files_behind(
    along_world, tmp_path, monkeypatch
):
    """Where the cache cannot be written, the library is compiled into a scratch directory
    that is gone once casadi has loaded it (a forked helper ends with os._exit: no clean-up
    at exit), and the solver still solves."""
    import tempfile

    blocker = tmp_path / "not-a-directory"
    blocker.write_text("")
    monkeypatch.setenv("XDG_CACHE_HOME", str(blocker))
    scratch = tmp_path / "tmp"
    scratch.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(scratch))
    control = along_world.scenario.control
    mpc = SupportMpc(control, along_world.map_grid(), along_world.camera)
    assert list(scratch.iterdir()) == []
    require_c_compiler()
    plan = read_plan(along_world.scenario)
    work = predict_work(
        plan.work[3], 4, plan.work, control.horizon_steps, control.d_max_work_m, 0.1
    )
    result = mpc.solve(
        plan.supports[0][3],
        plan.supports[0],
        work.path,
        work.indices,
        along_world.sigma0_map().sigma_m,
        along_world.camera.observable,
    )
    assert result.status == CONVERGED


def _blocked_case(world, mpc: SupportMpc):
    """A support above the deck's edge, the work UAV hovering under the deck: no sight line."""
    yhat = np.array([0.0, 6.0, 10.0])
    work = np.array([0.0, -3.0, 7.0])
    horizon = mpc.horizon
    waypoints = np.repeat(yhat[None], 2, axis=0)
    assert not world.camera.observable(yhat[None], work[None])[0]
    g = world.sigma0_map().sigma_m
    warm, plan = None, None
    for _ in range(4):  # a few cycles, warm-started, the work UAV holding still
        plan = mpc.solve(
            yhat,
            waypoints,
            np.repeat(work[None], horizon + 1, axis=0),
            np.ones(horizon + 1, dtype=int),
            g,
            world.camera.observable,
            warm,
        )
        yhat, warm = plan.path[0], plan.path
    return plan, work


def _with_control(world, **changes) -> SupportMpc:
    from dataclasses import replace

    control = replace(world.scenario.control, **changes)
    sigma0 = world.sigma0_map().sigma_m if control.support_max_sigma0_m < 1e6 else None
    return SupportMpc(control, world.map_grid(), world.camera, sigma0)


def test_los_penalty_brings_a_blocked_support_back_into_sight(along_world):
    mpc = _with_control(along_world, los_penalty="visible-point")
    plan, work = _blocked_case(along_world, mpc)
    # The commanded first steps see it (later ones head back to the blocked terminal waypoint).
    assert along_world.camera.observable(plan.path[:2], work[None]).all()
    sigma0 = along_world.sigma0_map().sigma_m.reshape(along_world.map_grid().shape)
    usable = hermite_zero_slope(sigma0, along_world.map_grid(), plan.path)
    assert np.all(usable <= along_world.scenario.control.support_max_sigma0_m + 1e-3)


def test_the_papers_penalty_form_pulls_toward_the_work_uav_not_into_sight(along_world):
    """w_penalty |v_w - v|^2 is smallest straight above the work UAV, on the deck: blocked."""
    mpc = _with_control(along_world, los_penalty="paper")
    plan, work = _blocked_case(along_world, mpc)
    assert not along_world.camera.observable(plan.path[-1:], work[None])[0]
    assert np.linalg.norm(plan.path[-1] - work) < np.linalg.norm([0.0, 9.0, 3.0]) - 2.0


def test_supports_stay_out_of_the_structures_gnss_shadow(along_world):
    grid = along_world.map_grid()
    sigma0 = along_world.sigma0_map().sigma_m.reshape(grid.shape)
    limit = along_world.scenario.control.support_max_sigma0_m
    kept_out, _ = _blocked_case(along_world, _with_control(along_world, los_penalty="paper"))
    assert np.all(hermite_zero_slope(sigma0, grid, kept_out.path) <= limit + 1e-3)
    unsafe = {"min_separation_m": 0.0, "clearance_m": 0.0}  # the margins would keep it out too
    free, _ = _blocked_case(
        along_world,
        _with_control(along_world, los_penalty="paper", support_max_sigma0_m=1e9, **unsafe),
    )
    assert np.max(hermite_zero_slope(sigma0, grid, free.path)) > limit  # into the deck


def test_anchors_are_the_nearest_visible_points_shell_by_shell(along_world):
    """The anchor search (every blocked step and its first shell judged together) returns what
    judging each step and then each shell on its own returns, for blocked steps all around the
    bridge; a step that sees is anchored at the work UAV."""
    mpc = _with_control(along_world, los_penalty="visible-point")
    control, camera = mpc.control, along_world.camera

    def shell_by_shell(start, work, fallback):
        for radius in (0.0, *mpc._anchors._shell_radii):
            points = start[None] if radius == 0 else start + radius * mpc._anchors._directions
            usable = hermite_zero_slope(mpc.sigma0, mpc.grid, points)
            points = points[usable <= control.support_max_sigma0_m]
            if len(points) == 0:
                continue
            seen = points[camera.observable(points, work[None])]
            if len(seen):
                return seen[np.argmin(np.linalg.norm(seen - work, axis=1))]
        return fallback

    rng = np.random.default_rng(6)
    work = np.array([0.0, -3.0, 7.0])  # under the deck's edge
    fallback = np.array([99.0, 99.0, 99.0])
    found_at = set()
    horizon = control.horizon_steps
    works, fallbacks = np.repeat(work[None], horizon, axis=0), np.full((horizon, 3), 99.0)
    for _ in range(40):  # a horizon's blocked steps are judged together
        starts = rng.uniform([-15, -12, 1], [15, 12, 13], (horizon, 3))
        blocked = rng.random(horizon) < 0.8
        got = mpc._anchors(starts, works, fallbacks, blocked)
        for start, anchor, is_blocked in zip(starts, got, blocked, strict=True):
            expected = shell_by_shell(start, work, fallback) if is_blocked else work
            np.testing.assert_array_equal(anchor, expected)
            if is_blocked:
                found_at.add(round(float(np.linalg.norm(expected - start)), 6))
    assert 0.0 in found_at and len(found_at) > 3  # the step itself, first and further shells

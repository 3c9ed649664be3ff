"""The support MPC's solver against others on the same problems: SLSQP (scipy) and casadi
interpreting the NLP (no C compiler), each over the compiled fatrop solve."""

from __future__ import annotations

import statistics
import time


def interpreted_over_compiled(world, plan, indices=range(2, 12)) -> float:
    """Median plan time without a C compiler (casadi interprets the NLP) over the compiled
    one's, on the three supports' problems at ten waypoints (the same plans either way)."""
    import numpy as np

    from ground_station.control.work_mpc import predict_work
    from ground_station.support_mpc.mpc import SupportMpc

    control, grid, sigma0 = world.scenario.control, world.map_grid(), world.sigma0_map().sigma_m
    compiled = SupportMpc(control, grid, world.camera, sigma0)
    interpreted = SupportMpc(control, grid, world.camera, sigma0, compiled=False)
    requests = []
    for i in indices:
        work = predict_work(
            plan.work[i], i + 1, plan.work, control.horizon_steps, control.d_max_work_m, 0.1
        )
        for n, waypoints in enumerate(plan.supports):
            yhat = waypoints[i] + np.array([0.3, -0.2, 0.1])
            requests.append(
                compiled.request(
                    f"support-{n + 1}", yhat, waypoints, work.path, work.indices, sigma0
                )
            )
    medians = []
    for mpc in (compiled, interpreted):
        times = []
        for request in requests * 3:
            start = time.perf_counter()
            mpc.plan(request, world.camera.observable)
            times.append(time.perf_counter() - start)
        medians.append(statistics.median(times))
    return medians[1] / medians[0]


def scipy_over_casadi(world, plan, problems: int) -> float:
    """Median time ratio SLSQP / our solver on the same support-MPC problems (optima within
    1 cm)."""
    from ground_station.support_mpc.mpc import SupportMpc

    mpc = SupportMpc(world.scenario.control, world.map_grid(), world.camera)
    g = world.sigma0_map().sigma_m
    ratios = [_scipy_over_casadi_once(world, plan, mpc, g, i) for i in range(problems)]
    agreeing = [ratio for ratio in ratios if ratio is not None]
    return statistics.median(agreeing) if agreeing else float("nan")


def _scipy_over_casadi_once(world, plan, mpc, g, i: int) -> float | None:
    """SLSQP's time over ours on support 1's i-th problem; None if their optima differ."""
    import numpy as np
    from scipy.optimize import minimize

    from ground_station.control.work_mpc import predict_work
    from ground_station.support_mpc.cost_check import support_cost_numpy

    control, grid = world.scenario.control, world.map_grid()
    u, waypoints = control.horizon_steps, plan.supports[0]
    yhat = waypoints[i] + np.array([0.3, -0.2, 0.1])
    work = predict_work(
        plan.work[i], i + 1, plan.work, u, control.d_max_work_m, control.arrival_tol_m
    )
    start = time.perf_counter()
    result = mpc.solve(yhat, waypoints, work.path, work.indices, g, world.camera.observable)
    casadi_s = time.perf_counter() - start
    targets, terminal = waypoints[work.indices[:u]], waypoints[work.indices[u]]

    def cost(x):
        return support_cost_numpy(
            x, yhat, targets, terminal, work.path[:u], result.blocked, g, grid, control,
            result.anchors,
        )  # fmt: skip

    def steps_left(x):
        v = x.reshape(-1, 3)
        steps = np.vstack([v[0] - yhat, np.diff(v, axis=0)])
        return control.d_max_support_m**2 - np.sum(steps**2, axis=1)

    start = time.perf_counter()
    reference = minimize(
        cost,
        mpc._initial_guess(yhat, terminal, None).ravel(),
        method="SLSQP",
        options={"maxiter": 300, "ftol": 1e-12},
        constraints=[{"type": "ineq", "fun": steps_left}],
    )
    scipy_s = time.perf_counter() - start
    if np.max(np.abs(reference.x.reshape(-1, 3) - result.path)) > 0.01:
        return None
    return scipy_s / casadi_s

"""MPC of each support UAV (paper 4.2.2): casadi + fatrop (or IPOPT), built once per run.

Decision variables: the U predicted positions V'_n. Cost, exactly the paper's four terms:

  C_GNSS     = sum_u w_GNSS G_s(v_u)
  C_interval = xi(|yhat - v_1|) + sum_u xi(|v_{u+1} - v_u|) + xi(|w_{n,k_{U+1}} - v_U|),
               xi(d) = w_interval d^2 if d <= d_max else w_penalty d^2
  C_waypoint = sum_u w_waypoint |v_u - w_{n,k_u}|^2
  C_relative = sum_u (w_relative, or w_penalty if not observable) |v^(w)_u - v_u|^2

Observability (range and line of sight between V^(w)_u and v_u) is not differentiable: it is
evaluated on the initial guess (the previous solution shifted by one step), held fixed during
the solve, and the problem is solved once more if the solution's flags differ (MODEL.md),
with a step blocked at either held blocked: taking the solution's flags alone flip-flops
between two paths, each blocked where the other's flags say it is not.

The terminal xi jumps at d_max, and an interior-point solver cycles across a jump until its
iteration limit. Its minimum is found exactly from two smooth problems instead: *near*
(|w - v_U| <= d_max, weight w_interval) and *far* (no bound, weight w_penalty). The lower of
the two, costed with the true xi, is the minimum: far's optimum is either beyond d_max (then
it is the far side's minimum) or within it (then near is at least as good). Far is skipped
when near's cost is below any cost the far side can have (w_penalty d_max^2 + w_GNSS U
min G), or when the terminal is out of reach, where only far is feasible.
"""

from __future__ import annotations

import contextlib
import hashlib
import itertools
import os
import shutil
import subprocess
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import casadi as ca
import numpy as np

from ground_station.casadi_buffer import BufferedFunction
from ground_station.localizability import hermite_zero_slope, inlined_hermite
from mission.config.settings import ControlSettings
from mission.world.camera import CameraModel
from mission.world.grid import VoxelGrid

IPOPT_OPTIONS = {
    "ipopt.print_level": 0,
    "ipopt.sb": "yes",
    "print_time": False,
    "calc_lam_p": False,  # unused; its gradient over the G window costs more than the solve
    "ipopt.max_iter": 50,
    "ipopt.tol": 1e-4,  # positions to ~0.1 mm; 1e-6 cost 25 % more iterations for nothing
    "ipopt.acceptable_tol": 1e-4,
    "ipopt.warm_start_init_point": "yes",
    "ipopt.hessian_approximation": "exact",  # measured: 3x fewer ms than L-BFGS here
    # MUMPS's matching-based permutation and scaling are for hard large systems; here they
    # cost 5 % of a solve and change the solutions by 1e-14 (600 recorded problems)
    "ipopt.mumps_permuting_scaling": 0,
}
# fatrop runs IPOPT's algorithm (filter line search, same barrier defaults) without IPOPT's
# per-solve set-up of its objects and of MUMPS, which is ~90 % of a 15-variable solve: 3x
# fewer ms. One dense stage ("none") is all 15 variables need.
FATROP_OPTIONS = {
    "structure_detection": "none",
    "print_time": False,
    "calc_lam_p": False,
    # bound_push as IPOPT's warm start has it: the guess is the previous plan, shifted
    "fatrop": {"print_level": 0, "tol": 1e-4, "max_iter": 50, "bound_push": 1e-3},
}
SOLVER_OPTIONS = {"fatrop": FATROP_OPTIONS, "ipopt": IPOPT_OPTIONS}
# -O1: as fast a solve as -O2 (1,220 recorded solves, bit-identical results) and the
# generated ~1.2 MB of C compiles in 5.8 s instead of 8.6 s
COMPILE_FLAGS = ["-O1", "-fPIC", "-shared"]
ESCAPE_STARTS = 1  # escape starts solved: the cheapest of six where it starts
CONVERGED = "SOLVER_RET_SUCCESS"  # casadi's status for a solve that met its tolerance


@dataclass(frozen=True)
class NlpBuild:
    """One NLP to compile: the solver's name and casadi plugin, the NLP (keys x, p, f, g) and
    the solver's options."""

    name: str
    plugin: str
    nlp: dict[str, ca.MX]
    options: dict


def compiled_nlps(builds: list[NlpBuild], fallback_dir: Callable[[], str]) -> list[str | None]:
    """For each build, the functions its casadi solver needs, compiled into a shared library
    with the system C compiler (about 1.5x faster solves than interpreting them), or None
    without one. The libraries not yet cached are compiled at the same time, one compiler
    process each.

    A library is cached (under ``$XDG_CACHE_HOME`` or ``~/.cache``) by the hash of the
    serialised NLP, the solver's name, plugin and options, the casadi version, the compiler
    and its flags: a run after the first builds no solver from the expressions, generates no
    C and compiles nothing. The C sources are generated in a scratch directory that is gone on
    return; where the cache cannot be written, the libraries go to ``fallback_dir()``.
    """
    compiler = shutil.which("gcc") or shutil.which("cc")
    libraries: list[str | None] = [None] * len(builds)
    if compiler is None:
        return libraries
    missing: dict[int, str] = {}
    for index, build in enumerate(builds):
        library_name = _library_name(compiler, build)
        cached = _cache_dir() / library_name
        if cached.is_file():
            libraries[index] = str(cached)
        else:
            missing[index] = library_name
    if not missing:
        return libraries
    with tempfile.TemporaryDirectory(prefix="support-mpc-c-") as scratch:
        sources: dict[int, tuple[str, Path]] = {}
        for index, library_name in missing.items():
            build = builds[index]
            solver = ca.nlpsol(build.name, build.plugin, build.nlp, build.options)
            source = f"support_mpc_nlp{index}.c"  # its stem must be a C identifier
            with contextlib.chdir(scratch):  # casadi writes the C file to the working directory
                solver.generate_dependencies(source)
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
                libraries[index] = library
                del sources[index]
    return libraries


def _library_name(compiler: str, build: NlpBuild) -> str:
    nlp = build.nlp
    functions = ca.Function("nlp", [nlp["x"], nlp["p"]], [nlp["f"], nlp["g"]])
    recipe = "\n".join(
        [
            f"{ca.__version__} {compiler} {' '.join(COMPILE_FLAGS)}",
            build.name,
            build.plugin,
            repr(sorted(build.options.items())),
            functions.serialize(),
        ]
    )
    return f"support_mpc_{hashlib.sha256(recipe.encode()).hexdigest()[:16]}.so"


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


@dataclass(frozen=True)
class PlanRequest:
    """One support's MPC problem: its estimate, the waypoints its horizon aims at, the work
    UAV's predicted path, the map window (corner; G's and sigma_0's values), the warm start."""

    name: str
    yhat: np.ndarray
    targets: np.ndarray  # (U, 3): w_{n,k_u}
    terminal: np.ndarray  # w_{n,k_{U+1}}
    work: np.ndarray  # (U, 3): the work UAV's predicted path
    corner: np.ndarray
    window: np.ndarray
    warm_start: np.ndarray | None
    escape: bool


@dataclass(frozen=True)
class SupportPlan:
    """The optimised local path V_n (U, 3) and how the solve went."""

    path: np.ndarray
    status: str
    solve_ms: float
    blocked: np.ndarray
    resolved: bool
    anchors: np.ndarray

    @property
    def command(self) -> np.ndarray:
        """The movement command: the first predicted position."""
        return self.path[0]


class SupportMpc:
    """One NLP, built once, solved for any support with its own parameters.

    G (and sigma_0, for the shadow constraint) enter through a cube of voxels around yhat_n,
    wide enough for everything the horizon can reach (U d_max plus a margin on each side), so
    a solve passes a few thousand values rather than the whole map; the cube's corner is a
    parameter.
    """

    def __init__(
        self,
        control: ControlSettings,
        grid: VoxelGrid,
        camera: CameraModel,
        sigma0: np.ndarray | None = None,
    ) -> None:
        self.control = control
        self.grid = grid
        self.camera = camera
        self.sigma0 = (
            None if sigma0 is None else np.asarray(sigma0, dtype=float).reshape(grid.shape)
        )
        self.horizon = control.horizon_steps
        reach = control.horizon_steps * control.d_max_support_m + grid.voxel_m
        half = int(np.ceil(reach / grid.voxel_m))
        self.window = tuple(min(2 * half + 1, n) for n in grid.shape)
        self._window_grid = VoxelGrid(np.zeros(3), grid.voxel_m, self.window)
        self._solvers, self._cost = self._build()
        cube = np.array(list(itertools.product((-1.0, 0.0, 1.0), repeat=3)))
        cube = cube[np.any(cube != 0, axis=1)]
        self._directions = cube / np.linalg.norm(cube, axis=1, keepdims=True)
        reach = control.horizon_steps * control.d_max_support_m
        self._shell_radii = np.arange(0.5, reach + 1e-9, 0.5)
        d_max_sq = control.d_max_support_m**2
        steps = np.full(self.horizon, d_max_sq * (1 + 1e-6))
        shadow = np.full(0 if sigma0 is None else self.horizon, control.support_max_sigma0_m)
        # Near keeps the terminal strictly inside d_max, so xi's lower weight applies to it;
        # far has no terminal constraint.
        self._upper_bounds = {
            "near": np.concatenate([steps, [d_max_sq * (1 - 1e-6)], shadow]),
            "far": np.concatenate([steps, shadow]),
        }

    def _build(self) -> tuple[dict[str, BufferedFunction], BufferedFunction]:
        """The solvers of the near and far branches (their functions compiled when a C
        compiler is there) and the cost function."""
        c, horizon = self.control, self.horizon
        sym = ca.MX
        v = sym.sym("v", 3, horizon)
        yhat = sym.sym("yhat", 3)
        targets = sym.sym("w", 3, horizon)
        terminal = sym.sym("terminal", 3)
        work = sym.sym("vw", 3, horizon)
        anchors = sym.sym("q", 3, horizon)  # where a blocked step is pulled (see _anchors)
        blocked = sym.sym("blocked", horizon)
        values = sym.sym("G", self._window_grid.n_voxels)
        prior = sym.sym("sigma0", 0 if self.sigma0 is None else self._window_grid.n_voxels)
        corner = sym.sym("corner", 3)

        terminal_weight = sym.sym("w_terminal")  # xi's weight on the branch being solved

        def sq(a):
            return ca.sumsqr(a)

        hermite = inlined_hermite(self._window_grid)  # G_s and the prior's, per step

        # Steps are also bounded hard (below), where xi(d) = w_interval d^2 exactly: writing it
        # so keeps the cost smooth. The terminal link is solved per branch (module docstring).
        cost = c.w_interval * sq(yhat - v[:, 0])
        for u in range(horizon):
            cost += c.w_gnss * hermite(v[:, u] - corner, values)
            cost += c.w_waypoint * sq(v[:, u] - targets[:, u])
            cost += (1 - blocked[u]) * c.w_relative * sq(work[:, u] - v[:, u])
            cost += blocked[u] * c.w_penalty * sq(anchors[:, u] - v[:, u])
            if u + 1 < horizon:
                cost += c.w_interval * sq(v[:, u + 1] - v[:, u])
        terminal_sq = sq(terminal - v[:, horizon - 1])
        cost += terminal_weight * terminal_sq
        parameters = ca.vertcat(
            yhat,
            ca.vec(targets),
            terminal,
            ca.vec(work),
            terminal_weight,
            ca.vec(anchors),
            blocked,
            corner,
            values,
            prior,
        )
        # The vehicle cannot fly faster than s_max: each predicted step is also bounded hard
        # (the paper's penalty alone lets a discontinuous cost trap the solver beyond d_max).
        steps = [sq(v[:, 0] - yhat)] + [sq(v[:, u + 1] - v[:, u]) for u in range(horizon - 1)]
        # Stay where the prior map (structure and sky, no zones) predicts a usable fix: the
        # paper's LOS penalty pulls a blocked support straight at the work UAV, i.e. under the
        # deck, where it would lose its fix (and fly into the structure).
        shadow = (
            []
            if self.sigma0 is None
            else [hermite(v[:, u] - corner, prior) for u in range(horizon)]
        )
        cost_function = ca.Function(
            "support_mpc_cost", [ca.vec(v), parameters], [cost], ["x", "p"], ["f"]
        )
        # With an infinite bound on far's terminal row fatrop failed 99 of 1,220 recorded
        # solves and carried the failure into the solves after it (plans then depended on the
        # order of solving); without the row it solves them all, as IPOPT does. No bound of
        # either branch is infinite.
        constraints = {
            "near": ca.vertcat(*steps, terminal_sq, *shadow),
            "far": ca.vertcat(*steps, *shadow),
        }
        plugin = c.mpc_solver
        options = SOLVER_OPTIONS[plugin]
        unbounded = {"lbx": -np.inf, "ubx": np.inf, "lbg": -np.inf}
        builds = [
            NlpBuild(
                f"support_mpc_{branch}",
                plugin,
                {"x": ca.vec(v), "p": parameters, "f": cost, "g": g},
                options,
            )
            for branch, g in constraints.items()
        ]
        solvers = {}
        with contextlib.ExitStack() as scratch:  # for libraries the cache cannot take

            def private_directory() -> str:
                return scratch.enter_context(tempfile.TemporaryDirectory(prefix="support-mpc-"))

            libraries = compiled_nlps(builds, private_directory)
            for branch, build, library in zip(constraints, builds, libraries, strict=True):
                loaded = build.nlp if library is None else library
                solver = ca.nlpsol(build.name, plugin, loaded, options)
                solvers[branch] = BufferedFunction(solver, ("x", "f"), unbounded)
        # casadi has loaded the libraries: their files may go (no clean-up left for the exit,
        # which a forked helper makes with os._exit)
        return solvers, BufferedFunction(cost_function, ("f",))

    def window_of(self, yhat: np.ndarray, g_values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(corner of the window in world coordinates, the values the NLP takes there: G's
        and then sigma_0's, each first-axis-fastest)."""
        shape = np.array(self.grid.shape)
        size = np.array(self.window)
        centre = self.grid.index_of(np.asarray(yhat)[None])[0]
        low = np.clip(centre - size // 2, 0, shape - size)
        cube = tuple(slice(low[a], low[a] + size[a]) for a in range(3))
        corner = self.grid.origin_m + self.grid.voxel_m * low
        maps = [np.asarray(g_values).reshape(self.grid.shape)[cube].ravel(order="F")]
        if self.sigma0 is not None:
            maps.append(self.sigma0[cube].ravel(order="F"))
        return corner, np.concatenate(maps)

    def solve(
        self,
        yhat: np.ndarray,
        support_waypoints: np.ndarray,
        work_path: np.ndarray,
        work_indices: np.ndarray,
        g_values: np.ndarray,
        observable,
        warm_start: np.ndarray | None = None,
        escape: bool = False,
    ) -> SupportPlan:
        """Optimise V_n (``g_values``: G as a 3-D array; ``observable(a, b)``: rows of b
        observable from rows of a)."""
        return self.plan(
            self.request(
                "", yhat, support_waypoints, work_path, work_indices, g_values, warm_start, escape
            ),
            observable,
        )

    def request(
        self,
        name: str,
        yhat: np.ndarray,
        support_waypoints: np.ndarray,
        work_path: np.ndarray,
        work_indices: np.ndarray,
        g_values: np.ndarray,
        warm_start: np.ndarray | None = None,
        escape: bool = False,
    ) -> PlanRequest:
        """Everything one support's solve needs, G cut down to the window around yhat."""
        horizon = self.horizon
        corner, window = self.window_of(yhat, g_values)
        return PlanRequest(
            name,
            np.asarray(yhat, dtype=float),
            support_waypoints[work_indices[:horizon]],
            support_waypoints[work_indices[horizon]],
            work_path[:horizon],
            corner,
            window,
            warm_start,
            escape,
        )

    def plan(self, request: PlanRequest, observable) -> SupportPlan:
        """Optimise V_n for one request (``observable(a, b)``: rows of b observable from rows
        of a)."""
        yhat, targets, terminal, work = (
            request.yhat,
            request.targets,
            request.terminal,
            request.work,
        )
        corner, window = request.corner, request.window
        fixed = np.concatenate([yhat, targets.ravel(), terminal, work.ravel()])
        guess = self._initial_guess(yhat, terminal, request.warm_start)
        start = time.perf_counter()
        blocked = ~observable(guess, work)
        anchors = self.anchors(guess, work, targets, blocked)
        flags = np.concatenate([anchors.ravel(), blocked.astype(float), corner, window])
        path, status, cost = self._solve_once(fixed, flags, guess)
        if request.escape:  # G_s is flat at voxel centres: also start from paths leaving each way
            for candidate in self._escape_guesses(yhat, fixed, flags):
                tried = self._solve_once(fixed, flags, candidate)
                if tried[2] < cost - 1e-9:
                    path, status, cost = tried
        resolved = False
        after = ~observable(path, work)
        if np.any(after != blocked):
            blocked, resolved = blocked | after, True  # blocked either way: held blocked
            anchors = self.anchors(path, work, targets, blocked)
            flags = np.concatenate([anchors.ravel(), blocked.astype(float), corner, window])
            path, status, _ = self._solve_once(fixed, flags, path)
        elapsed = (time.perf_counter() - start) * 1000
        return SupportPlan(path, status, elapsed, blocked, resolved, anchors)

    def _initial_guess(
        self, yhat: np.ndarray, terminal: np.ndarray, warm_start: np.ndarray | None
    ) -> np.ndarray:
        if warm_start is not None:
            return np.vstack([warm_start[1:], warm_start[-1:]])
        fractions = np.arange(1, self.horizon + 1)[:, None] / (self.horizon + 1)
        return yhat + (terminal - yhat) * fractions

    def _solve_once(self, fixed: np.ndarray, flags: np.ndarray, guess: np.ndarray):
        """The minimum over both branches of the terminal xi: (path, status, true cost)."""
        c, horizon = self.control, self.horizon
        yhat, terminal = fixed[:3], self._terminal_of(fixed)
        reach = (horizon + 1) * c.d_max_support_m
        best = None
        if np.linalg.norm(terminal - yhat) <= reach:
            best = self._solve_branch(fixed, flags, guess, "near")
            start = 3 * horizon + horizon + 3  # G's window, after the anchors, flags, corner
            g_min = flags[start : start + self._window_grid.n_voxels].min()
            far_floor = c.w_penalty * c.d_max_support_m**2 + c.w_gnss * horizon * g_min
            if best[1] == CONVERGED and best[2] <= far_floor:
                return best
        far = self._solve_branch(fixed, flags, guess, "far")
        tried = [plan for plan in (best, far) if plan is not None]
        converged = [plan for plan in tried if plan[1] == CONVERGED]
        return min(converged or tried, key=lambda plan: plan[2])

    def _solve_branch(self, fixed, flags, guess, branch: str):
        """One branch's solve from ``guess``: (path, casadi's status, true cost)."""
        c = self.control
        solver = self._solvers[branch]
        weight = c.w_interval if branch == "near" else c.w_penalty
        result = solver(
            x0=guess.ravel(),
            p=np.concatenate([fixed, [weight], flags]),
            ubg=self._upper_bounds[branch],
        )
        status = solver.stats()["unified_return_status"]
        path = result["x"].reshape(self.horizon, 3)
        terminal_sq = float(np.sum((self._terminal_of(fixed) - path[-1]) ** 2))
        cost = float(result["f"][0]) + (self._xi_weight(terminal_sq) - weight) * terminal_sq
        return path, status, cost

    def _terminal_of(self, fixed: np.ndarray) -> np.ndarray:
        """The terminal waypoint w_{n,k_{U+1}} inside the fixed parameters."""
        return fixed[3 + 3 * self.horizon : 6 + 3 * self.horizon]

    def _xi_weight(self, terminal_sq: float) -> float:
        """The paper's xi weight at a squared distance: w_interval up to d_max, else w_penalty."""
        c = self.control
        return c.w_interval if terminal_sq <= c.d_max_support_m**2 else c.w_penalty

    def anchors(
        self, guess: np.ndarray, work: np.ndarray, targets: np.ndarray, blocked: np.ndarray
    ) -> np.ndarray:
        """Where the LOS penalty pulls each blocked step.

        ``paper``: the work UAV itself. ``visible-point``: the step's guess when it sees the
        work UAV (a step held blocked by the re-solve), else the nearest point around it (26
        directions, shells up to the horizon's reach) that sees the work UAV and has a usable
        prior fix, the nearest to the work UAV among equals; the pre-planned waypoint when there
        is none.
        """
        anchors = np.array(work, dtype=float)
        if self.control.los_penalty == "paper" or not np.any(blocked):
            return anchors
        for u in np.flatnonzero(blocked):
            anchors[u] = self._nearest_visible(guess[u], work[u], targets[u])
        return anchors

    def _nearest_visible(self, start: np.ndarray, work: np.ndarray, fallback: np.ndarray):
        # The step itself, then shell after shell; the step and the first shell are judged in
        # one evaluation (nine anchors in ten are found there, and a point's verdict does not
        # depend on the points judged with it).
        first = np.vstack([start[None], start + self._shell_radii[0] * self._directions])
        sees = self._sees_with_a_fix(first, work)
        if sees[0]:
            return start
        shells = [(first[1:], sees[1:])]
        shells += [(start + r * self._directions, None) for r in self._shell_radii[1:]]
        for points, verdict in shells:
            seen = points[self._sees_with_a_fix(points, work) if verdict is None else verdict]
            if len(seen):
                return seen[np.argmin(np.linalg.norm(seen - work, axis=1))]
        return fallback

    def _sees_with_a_fix(self, points: np.ndarray, work: np.ndarray) -> np.ndarray:
        """Where a point has a usable prior fix and sees the work UAV."""
        usable = np.ones(len(points), dtype=bool)
        if self.sigma0 is not None:
            sigma = hermite_zero_slope(self.sigma0, self.grid, points)
            usable = sigma <= self.control.support_max_sigma0_m
        return usable & self.camera.observable(points, work[None])

    def _escape_guesses(self, yhat: np.ndarray, fixed: np.ndarray, flags: np.ndarray):
        """Paths leaving at d_max per step along +-x, +-y or +-z for half the horizon, then
        heading straight for the terminal waypoint: the ESCAPE_STARTS of the six that cost
        least where they start."""
        horizon, d_max = self.horizon, self.control.d_max_support_m
        terminal = self._terminal_of(fixed)
        out = (horizon + 1) // 2
        paths = []
        for direction in np.vstack([np.eye(3), -np.eye(3)]):
            leaving = yhat + np.arange(1, out + 1)[:, None] * d_max * direction
            back = np.arange(1, horizon - out + 1)[:, None] / (horizon - out + 1)
            paths.append(np.vstack([leaving, leaving[-1] + (terminal - leaving[-1]) * back]))
        costs = [self.cost(fixed, flags, path) for path in paths]
        return [paths[i] for i in np.argsort(costs, kind="stable")[:ESCAPE_STARTS]]

    def cost(self, fixed: np.ndarray, flags: np.ndarray, path: np.ndarray) -> float:
        """The true cost of ``path`` (terminal xi on its side of d_max)."""
        terminal_sq = float(np.sum((self._terminal_of(fixed) - path[-1]) ** 2))
        weight = self._xi_weight(terminal_sq)
        return float(self._cost(x=path.ravel(), p=np.concatenate([fixed, [weight], flags]))["f"][0])


def support_cost_numpy(
    path: np.ndarray,
    yhat: np.ndarray,
    targets: np.ndarray,
    terminal: np.ndarray,
    work: np.ndarray,
    blocked: np.ndarray,
    g_values: np.ndarray,
    grid: VoxelGrid,
    control: ControlSettings,
    anchors: np.ndarray | None = None,
) -> float:
    """The same cost in numpy over the whole map (an independent check of the casadi model);
    ``anchors`` default to the work UAV's path (the paper's penalty)."""
    c = control
    path = np.asarray(path, dtype=float).reshape(-1, 3)

    def sq(a: np.ndarray) -> float:
        return float(np.sum(np.asarray(a) ** 2))

    cost = c.w_interval * sq(yhat - path[0])
    cost += c.w_interval * sum(sq(b - a) for a, b in itertools.pairwise(path))
    terminal_sq = sq(terminal - path[-1])
    limit = c.d_max_support_m**2
    cost += (c.w_interval if terminal_sq <= limit else c.w_penalty) * terminal_sq
    cost += c.w_gnss * float(np.sum(hermite_zero_slope(g_values, grid, path)))
    cost += c.w_waypoint * sq(path - targets)
    anchors = work if anchors is None else anchors
    free = ~np.asarray(blocked, dtype=bool)
    cost += c.w_relative * float(np.sum((work - path)[free] ** 2))
    cost += c.w_penalty * float(np.sum((anchors - path)[~free] ** 2))
    return cost

"""The support MPC keeps its margins over the whole horizon (checked on its plans against
independent distances: numpy between UAVs, trimesh to the bridge) where the paper's form hugs
the deck, and the work UAV waits rather than step into a margin."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
import trimesh

from ground_station.control.plan import plan, work_must_wait
from ground_station.control.run_context import build_run_context
from ground_station.control.work_mpc import predict_work
from ground_station.support_mpc.branches import CONVERGED, TerminalBranches
from ground_station.support_mpc.margins import SLOTS, Margins
from ground_station.support_mpc.mpc import SupportMpc
from ground_station.support_mpc.nlp import SOFT
from mission.config.scenario import load_scenario
from mission.link.plan_files import read_plan
from mission.world.model import KnownWorld, World


def _mpc(world: World, others: int) -> SupportMpc:
    return SupportMpc(
        world.scenario.control, world.map_grid(), world.camera, world.sigma0_map().sigma_m,
        others=others,
    )  # fmt: skip


@pytest.fixture(scope="module")
def worlds():
    safe = World(load_scenario("along"))
    paper = World(load_scenario("along", {"control.min_separation_m": 0, "control.clearance_m": 0}))
    return safe, paper


def _squeezed(world: World, mpc: SupportMpc):
    """Support 1 beside the deck's side (0.8 m from it) heading along it, with support 2
    parked out from its path: the cheapest plan runs along the deck, close past support 2; the
    corridor between the two margins (as the safe settings plan them, from the deck and from
    support 2) is open, 0.5 m wide."""
    plan_ = read_plan(world.scenario)
    control = load_scenario("along").control  # the safe settings place support 2
    allowance = control.estimate_allowance_m
    corridor = control.clearance_m + allowance + control.min_separation_m + 2 * allowance + 0.5
    horizon = world.scenario.control.horizon_steps
    yhat = np.array([-6.0, 5.8, 8.5])
    waypoints = np.array([yhat + [2.0 * i, -0.3, 0.0] for i in range(15)])
    work = predict_work(plan_.work[6], 6, plan_.work, horizon, 0.3, 0.1)
    other = np.repeat([[-3.5, 5.0 + corridor, 8.5]], horizon, axis=0)  # the deck's side: y = 5
    others = np.array([work.path[:horizon], other, other + [0.0, 30.0, 0.0]])
    request = mpc.request(
        "support-1", yhat, waypoints, work.path, work.indices, world.sigma0_map().sigma_m,
        others=others,
    )  # fmt: skip
    return mpc.plan(request, world.camera.observable), others


def test_the_support_mpc_keeps_every_margin_over_its_horizon(worlds):
    safe, paper = worlds
    control = safe.scenario.control
    allowance = control.estimate_allowance_m
    query = trimesh.proximity.ProximityQuery(safe.structure.mesh)
    kept, others = _squeezed(safe, _mpc(safe, 3))
    assert kept.status == CONVERGED
    apart = np.linalg.norm(kept.path[None] - others, axis=2).min()
    assert apart >= control.min_separation_m + 2 * allowance - 1e-3
    clear = np.abs(query.signed_distance(kept.path)).min()
    assert clear >= control.clearance_m + allowance - 1e-3
    free, _ = _squeezed(paper, _mpc(paper, 3))  # the paper's form hugs the deck
    assert np.abs(query.signed_distance(free.path)).min() < control.clearance_m + allowance


def test_the_work_uav_waits_rather_than_step_into_a_margin(along):
    known = KnownWorld(along)
    plan_ = read_plan(along)
    waypoints = {
        "work": plan_.work,
        **{f"support-{n + 1}": s for n, s in enumerate(plan_.supports)},
    }
    context, state = build_run_context(known, waypoints, True, 0)
    state.xhat = plan_.work[0].copy()
    ahead = plan_.work[1] - plan_.work[0]
    ahead /= np.linalg.norm(ahead)
    state.yhat["support-1"] = state.xhat + 2.1 * ahead  # just outside 2 m; the next step is in
    formation = plan(state, context, list(context.support_waypoints))
    assert work_must_wait(state, state.xhat + 0.3 * ahead, context)
    np.testing.assert_array_equal(formation.work.command, state.xhat)
    state.yhat["support-1"] = state.xhat - 1.5 * ahead  # inside already, behind: stepping away
    formation = plan(state, context, list(context.support_waypoints))
    assert np.linalg.norm(formation.work.command - state.xhat) > 0.1


def _reference_half_spaces(margins, guess, yhat, others):
    """The half-spaces of each step from the definition, in numpy: every other UAV's, every
    structure piece's (the general closest-point code) and the ground's, the ``slots`` least
    slack at the guess kept (stable), unused slots padded."""
    distance, closest, normal = margins.proximity.closest(guess)
    rows = []
    for u, g in enumerate(guess):
        spaces = []
        for other in others[: margins.other_slots]:
            away = g - other[u]
            n = away / np.linalg.norm(away)
            spaces.append((n, n @ other[u] + margins.separation))
        if margins.clearance > 0:
            for piece in range(margins.proximity.pieces):
                if distance[u, piece] > margins._reach_m:
                    spaces.append((np.zeros(3), -1.0))
                else:
                    n = normal[u, piece]
                    spaces.append((n, n @ closest[u, piece] + margins.clearance))
            spaces.append((np.array([0.0, 0.0, 1.0]), margins.clearance))
        if len(spaces) > margins.slots:
            order = np.argsort([n @ g - b for n, b in spaces], kind="stable")
            spaces = [spaces[i] for i in order[: margins.slots]]
        spaces += [(np.zeros(3), -1.0)] * (margins.slots - len(spaces))
        rows.append(spaces)
    normals = [n for row in rows for n, _ in row]
    return np.concatenate([np.ravel(normals), [b for row in rows for _, b in row]])


@pytest.mark.parametrize("structure", ["boxes", "mesh file"])
def test_the_half_spaces_are_those_of_their_definition(structure, write_scenario, tmp_path):
    """Random guesses, some inside the structure, against :func:`_reference_half_spaces`."""
    if structure == "boxes":
        world = World(load_scenario("along"))
    else:
        roof = trimesh.creation.box(extents=[40.0, 6.0, 1.0])
        roof.apply_translation([0.0, 0.0, 8.5])
        roof.export(str(tmp_path / "roof.stl"))
        world = World(load_scenario(write_scenario(
            "world: {structure: {mesh_file: roof.stl, primitives: "
            "[{name: post, min_m: [-2, -8, 0], max_m: [2, -6, 8]}]}}\n"
        )))  # fmt: skip
    margins = Margins(world.scenario.control, world.structure, others=3)
    assert margins.slots == SLOTS
    rng = np.random.default_rng(4)
    deck = world.structure.boxes[0]
    for trial in range(300):
        guess = rng.uniform([-15, -10, 0.2], [15, 10, 12], (5, 3))
        if trial % 5 == 0:  # a step inside a box
            guess[2] = rng.uniform(deck.min_m, deck.max_m)
        yhat = rng.uniform([-15, -10, 0.2], [15, 10, 12])
        others = rng.uniform([-15, -10, 0.2], [15, 10, 12], (3, 5, 3))
        ours = margins.parameters(guess, yhat, others)
        np.testing.assert_allclose(
            ours, _reference_half_spaces(margins, guess, yhat, others), rtol=0, atol=1e-12
        )


YHAT = np.array([-6.0, 12.0, 8.5])  # support 1 in the open, beside the bridge


def _beside_the_bridge(world: World, mpc: SupportMpc, parked, terminal=None):
    """Support 1's request at YHAT, every waypoint there (the terminal one at ``terminal`` if
    given), support 2 parked at ``parked`` and support 3 far off."""
    plan_ = read_plan(world.scenario)
    horizon = world.scenario.control.horizon_steps
    work = predict_work(plan_.work[6], 6, plan_.work, horizon, 0.3, 0.1)
    waypoints = np.repeat([YHAT], 15, axis=0)
    if terminal is not None:
        waypoints[work.indices[horizon]] = terminal  # also the target of the later steps
    still = np.repeat([parked], horizon, axis=0)
    others = np.array([work.path[:horizon], still, still + [0.0, 30.0, 0.0]])
    return mpc.request(
        "support-1", YHAT, waypoints, work.path, work.indices, world.sigma0_map().sigma_m,
        others=others,
    )  # fmt: skip


def test_near_is_not_solved_where_far_beats_what_its_slacks_must_cost(worlds, monkeypatch):
    """A terminal waypoint inside another UAV's margin: near would have to break it (fatrop
    stalls on that problem); far, solved first, costs less than near's slacks at least would,
    and near is never solved."""
    safe, _ = worlds
    mpc = _mpc(safe, 3)
    parked = YHAT + [2.8, 0.0, 0.0]  # support 2, on the terminal waypoint
    request = _beside_the_bridge(safe, mpc, parked, terminal=parked)
    solved = []
    solve_branch = TerminalBranches._solve_branch

    def counted(self, fixed, flags, guess, branch):
        solved.append(branch)
        return solve_branch(self, fixed, flags, guess, branch)

    monkeypatch.setattr(TerminalBranches, "_solve_branch", counted)
    kept = mpc.plan(request, safe.camera.observable)
    assert kept.status == CONVERGED and "near" not in solved and "far" in solved
    control = safe.scenario.control
    apart = np.linalg.norm(kept.path - parked, axis=1).min()
    assert apart >= control.min_separation_m + 2 * control.estimate_allowance_m - 1e-3


def _forms_solved(monkeypatch) -> list[str]:
    """The solver forms (branch, or branch + SOFT) every solve of the test uses, in order."""
    solved: list[str] = []
    solve_form = TerminalBranches._solve_form

    def counted(self, fixed, flags, guess, branch, form):
        solved.append(form)
        return solve_form(self, fixed, flags, guess, branch, form)

    monkeypatch.setattr(TerminalBranches, "_solve_form", counted)
    return solved


def test_the_hard_form_is_solved_where_the_margins_can_be_kept_and_has_the_soft_ones_minimum(
    worlds, monkeypatch
):
    """The squeezed support can keep its margins: its plan comes from the hard form alone, and
    the soft form (the exact penalty), solved from the same start, finds the same path."""
    safe, _ = worlds
    mpc = _mpc(safe, 3)
    solved = _forms_solved(monkeypatch)
    kept, _ = _squeezed(safe, mpc)
    assert kept.status == CONVERGED and solved and not any(f.endswith(SOFT) for f in solved)
    monkeypatch.setattr(TerminalBranches, "_may_keep_margins", lambda *arguments: False)
    soft, _ = _squeezed(safe, mpc)
    assert soft.status == CONVERGED and all(f.endswith(SOFT) for f in solved[-2:])
    np.testing.assert_allclose(soft.path, kept.path, atol=5e-3)


def test_a_margin_out_of_reach_goes_straight_to_the_soft_form(worlds, monkeypatch):
    """Another UAV parked on the support's own estimate: the first step cannot leave its
    margin (3.5 m away, 1 m a step), so no hard form is tried, and the plan breaks the margin
    no more than it must (it flies straight away from the other UAV)."""
    safe, _ = worlds
    mpc = _mpc(safe, 3)
    parked = YHAT + [0.0, -0.5, 0.0]
    request = _beside_the_bridge(safe, mpc, parked)
    solved = _forms_solved(monkeypatch)
    planned = mpc.plan(request, safe.camera.observable)
    assert planned.status == CONVERGED and solved and all(f.endswith(SOFT) for f in solved)
    distance = np.linalg.norm(planned.path - parked, axis=1)
    assert distance[0] > 0.5 + 0.9  # close to a full step straight away


def test_a_failed_hard_solve_falls_back_to_the_soft_form(worlds, monkeypatch):
    """When the hard form does not converge, the same branch is solved in its soft form, and
    the plan is the soft form's."""
    safe, _ = worlds
    mpc = _mpc(safe, 3)
    solved = _forms_solved(monkeypatch)
    solve_form = TerminalBranches._solve_form  # the counting one

    def hard_fails(self, fixed, flags, guess, branch, form):
        path, status, cost = solve_form(self, fixed, flags, guess, branch, form)
        return (
            (path, "SOLVER_RET_LIMITED", cost) if not form.endswith(SOFT) else (path, status, cost)
        )

    monkeypatch.setattr(TerminalBranches, "_solve_form", hard_fails)
    planned, _ = _squeezed(safe, mpc)
    assert planned.status == CONVERGED
    assert [f for f in solved if not f.endswith(SOFT)]  # tried hard first
    for hard, after in itertools.pairwise(solved):
        if not hard.endswith(SOFT):
            assert after == hard + SOFT


@pytest.mark.parametrize("compiled", [True, False])
def test_the_half_spaces_function_gives_the_python_values_bit_for_bit(compiled):
    """The casadi function (compiled, or interpreted) against the plain-float definition, to
    the last bit, on random guesses with steps on other UAVs, on yhat too, and inside the deck
    (where it hands over to Python): the plans, and so the records, cannot change."""
    world = World(load_scenario("along"))
    control = world.scenario.control
    fast = Margins(control, world.structure, others=3, compiled=compiled)
    python = Margins(control, world.structure, others=3)
    python._function = None
    assert fast._function is not None
    rng = np.random.default_rng(7)
    deck = world.structure.boxes[0]
    for trial in range(400):
        guess = rng.uniform([-15, -10, 0.2], [15, 10, 12], (5, 3))
        yhat = rng.uniform([-15, -10, 0.2], [15, 10, 12])
        others = rng.uniform([-15, -10, 0.2], [15, 10, 12], (3, 5, 3))
        if trial % 4 == 1:  # a step on another UAV
            others[1, 3] = guess[3]
        if trial % 8 == 3:  # ... and yhat too
            others[2, 0] = guess[0]
            yhat = guess[0].copy()
        if trial % 10 == 5:  # a step inside the deck
            guess[2] = rng.uniform(deck.min_m, deck.max_m)
        ours = fast.parameters(guess, yhat, others)
        assert np.array_equal(ours, python.parameters(guess, yhat, others)), trial

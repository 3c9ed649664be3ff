"""The support-path planner, the shipped plan files and the zones placed on them."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mission.config.errors import InputError
from mission.config.scenario import load_scenario
from mission.link.plan_check import FILE_ROUNDING_M
from mission.link.plan_files import read_plan, vehicle_names
from mission.link.waypoints import read_waypoints
from mission.planning.planner import PlanningError, plan_supports
from mission.planning.zone_placement import inside, path_samples
from mission.world.model import World

ROUNDING_M = FILE_ROUNDING_M  # files hold 6 decimals of a degree (about 0.1 m)


@pytest.fixture(scope="module")
def shipped(along):
    return read_plan(along)


def test_shipped_plan_satisfies_the_planner_constraints(along_world, shipped):
    scenario = along_world.scenario
    work = shipped.work
    np.testing.assert_allclose(work, scenario.task.work_waypoints_m, atol=ROUNDING_M)
    assert shipped.supports.shape == (3, 15, 3)
    control = scenario.control
    reach = (
        control.s_max_support_m_s
        * np.linalg.norm(np.diff(work, axis=0), axis=1)
        / control.s_max_work_m_s
    )
    for path in shipped.supports:
        blocked = along_world.structure.segments_blocked(path, work)
        assert not blocked.any(), "every support waypoint sees its work waypoint"
        assert np.all(np.linalg.norm(path - work, axis=1) <= scenario.camera.range_m)
        assert np.all(np.linalg.norm(np.diff(path, axis=0), axis=1) <= reach + ROUNDING_M)
        sigma0 = along_world.gnss.sigma0(path)
        assert np.all(sigma0 <= 1.25 * 0.144), "open-sky GNSS quality where the lattice allows"
        assert not along_world.structure.contains(path).any()
    for i in range(15):
        points = shipped.supports[:, i]
        gaps = [np.linalg.norm(points[a] - points[b]) for a in range(3) for b in range(a + 1, 3)]
        assert min(gaps) >= scenario.planner.min_separation_m - ROUNDING_M


def test_shipped_files_round_trip_through_mavwp(along, tmp_path):
    from pymavlink import mavwp

    for name in vehicle_names(3):
        original = Path(along.task.waypoints_dir) / f"{name}.waypoints"
        loader = mavwp.MAVWPLoader()
        assert loader.load(str(original)) == 16  # home + 15 waypoints
        loader.save(str(tmp_path / name))
        assert (tmp_path / name).read_bytes() == original.read_bytes()


def test_along_zone_encloses_a_stretch_of_support_1s_path_only(shipped):
    zone = load_scenario("along").world.zones[0].box
    assert sorted(zone.size_m) == [1.0, 2.0, 5.0]
    support_1 = shipped.supports[0]
    stretches = [inside(zone, path_samples(support_1[i : i + 2])).sum() * 0.05 for i in range(14)]
    assert max(stretches) >= 2.0, "at least 2 m of one segment lies in the zone"
    for other in shipped.supports[1:]:
        assert not inside(zone, path_samples(other)).any()


def test_wall_zone_holds_w_1_6_and_no_other_supports_waypoint(shipped):
    zone = load_scenario("wall").world.zones[0].box
    assert sorted(zone.size_m) == [2.0, 5.0, 5.0]
    assert inside(zone, shipped.supports[0][5][None])[0]
    for other in shipped.supports[1:]:
        assert not inside(zone, other).any()


def _world_with(write_scenario, text: str) -> World:
    return World(load_scenario(str(write_scenario(text))))


def test_a_work_waypoint_inside_the_structure_is_refused(write_scenario):
    world = _world_with(write_scenario, "task: {work_waypoints_m: [[0, 0, 7], [0, 0, 8.5]]}\n")
    with pytest.raises(PlanningError, match=r"work_waypoints_m\[1\].*waypoint 2 .*inside"):
        plan_supports(world)


def test_a_work_waypoint_no_support_can_see_is_refused(write_scenario):
    shell = [  # a closed hollow box around (0, 0, 4)
        ("floor", [-2, -2, 2], [2, 2, 2.5]),
        ("roof", [-2, -2, 5.5], [2, 2, 6]),
        ("west", [-2, -2, 2.5], [-1.5, 2, 5.5]),
        ("east", [1.5, -2, 2.5], [2, 2, 5.5]),
        ("south", [-1.5, -2, 2.5], [1.5, -1.5, 5.5]),
        ("north", [-1.5, 1.5, 2.5], [1.5, 2, 5.5]),
    ]
    primitives = "".join(
        f"\n      - {{name: {n}, min_m: {lo}, max_m: {hi}}}" for n, lo, hi in shell
    )
    world = _world_with(
        write_scenario,
        f"""
world:
  structure:
    primitives:{primitives}
task: {{work_waypoints_m: [[10, -10, 4], [0, 0, 4]]}}
""",
    )
    with pytest.raises(PlanningError, match=r"work_waypoints_m\[1\].*no support can see"):
        plan_supports(world)


BAD_FILES = [
    ("header", "QGC WPL 100\n", "line 1", "first line"),
    ("columns", "QGC WPL 110\n0\t1\t3\t16\t0\t0\t0\t0\t35.1\t136.9\t7\n", "line 2", "12 values"),
    (
        "number",
        "QGC WPL 110\n0\t1\t3\t16\t0\t0\t0\t0\tnorth\t136.9\t7\t1\n",
        "line 2, column 9",
        "expected a number",
    ),
    (
        "integer",
        "QGC WPL 110\n0\t1\t3.5\t16\t0\t0\t0\t0\t35.1\t136.9\t7\t1\n",
        "line 2, column 3",
        "expected an integer",
    ),
    (
        "latitude",
        "QGC WPL 110\n0\t1\t3\t16\t0\t0\t0\t0\t95.0\t136.9\t7\t1\n",
        "line 2, column 9",
        "latitude out of range",
    ),
    (
        "order",
        "QGC WPL 110\n1\t1\t3\t16\t0\t0\t0\t0\t35.1\t136.9\t7\t1\n",
        "line 2, column 1",
        "out of order",
    ),
    ("empty", "QGC WPL 110\n", "", "holds no waypoints"),
]


@pytest.mark.parametrize(
    ("case", "text", "where", "problem"), BAD_FILES, ids=[c[0] for c in BAD_FILES]
)
def test_malformed_waypoint_files_name_file_line_and_column(tmp_path, case, text, where, problem):
    path = tmp_path / "bad.waypoints"
    path.write_text(text)
    with pytest.raises(InputError) as caught:
        read_waypoints(path)
    message = str(caught.value)
    assert str(path) in message and where in message and problem in message


def test_binary_and_missing_waypoint_files_are_reported(tmp_path):
    binary = tmp_path / "binary.waypoints"
    binary.write_bytes(b"\xff\xfe\x00QGC")
    with pytest.raises(InputError, match=r"binary\.waypoints: not UTF-8 text"):
        read_waypoints(binary)
    with pytest.raises(InputError, match=r"absent\.waypoints: cannot read"):
        read_waypoints(tmp_path / "absent.waypoints")

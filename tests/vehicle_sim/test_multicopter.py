"""The flying quadrotor as a vehicle's motion: the kinematic model's interface kept (belief,
estimate, hold, crash stop, the move it reports), and a real run whose vehicles fly it."""

from __future__ import annotations

import json

import numpy as np
import pytest

from mission.config.scenario import load_scenario
from tests.processes import EXIT_NOT_COMPLETED, mission
from vehicle_sim.dynamics.multicopter import Multicopter

VEHICLE = load_scenario("along").vehicle
STEP_S = 0.5


def test_it_believes_what_the_estimate_says_and_flies_from_there():
    body = Multicopter.at(np.array([0.0, 0.0, 10.0]), VEHICLE, STEP_S)
    body.set_estimate(np.array([0.5, 0.0, 10.0]))  # it is told it is 0.5 m east of the truth
    assert body.believed == pytest.approx([0.5, 0.0, 10.0])
    body.target = np.array([2.0, 0.0, 10.0])
    rng = np.random.default_rng(0)
    moves = [body.step(STEP_S, 3.0, rng, 0.0) for _ in range(30)]
    assert body.believed == pytest.approx([2.0, 0.0, 10.0], abs=0.02)
    assert body.truth == pytest.approx([1.5, 0.0, 10.0], abs=0.02)  # where the error takes it
    assert np.sum(moves, axis=0) == pytest.approx([1.5, 0.0, 0.0], abs=0.02)
    assert np.linalg.norm(body.velocity) < 0.05


def test_holding_stays_and_a_kick_moves_the_truth_not_the_belief():
    body = Multicopter.at(np.array([0.0, 0.0, 10.0]), VEHICLE, STEP_S)
    body.hold()
    believed = body.believed
    body.step(STEP_S, 3.0, np.random.default_rng(1), 0.3)
    truth_after_kick = body.truth
    assert body.believed == pytest.approx(believed, abs=1e-3)
    assert np.linalg.norm(truth_after_kick - believed) > 0.05


def test_a_crash_stops_it_dead_and_a_wrong_step_length_is_refused():
    body = Multicopter.at(np.array([0.0, 0.0, 10.0]), VEHICLE, STEP_S)
    body.target = np.array([5.0, 0.0, 10.0])
    body.step(STEP_S, 3.0, np.random.default_rng(2), 0.0)
    body.stop_at(np.array([1.0, 2.0, 3.0]))
    assert body.truth == pytest.approx([1.0, 2.0, 3.0]) and body.target is None
    assert np.linalg.norm(body.velocity) == 0 and body.believed == pytest.approx(body.truth)
    with pytest.raises(ValueError, match=r"steps of 0\.5 s"):
        body.step(0.25, 3.0, np.random.default_rng(2), 0.0)


@pytest.mark.slow
def test_a_run_with_multicopters_flies_its_first_minute(tmp_path):
    scenario = tmp_path / "flying.yaml"
    scenario.write_text(
        "extends: along\nvehicle: {dynamics: multicopter}\nrun: {timeout_s: 60}\n"
        "world: {wind: {speed_m_s: 3.0}}\n"
    )
    result = mission("run", str(scenario), "--out", str(tmp_path / "run"))
    assert result.returncode == EXIT_NOT_COMPLETED, result.stderr
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert summary["control_cycles"] == 120 and not summary["safety"]["contacts"]
    assert summary["work_error_m"]["mean"] < 0.5  # the formation localizes a flying work UAV
    tracking = summary["tracking_error_m"]  # a flying body lags the ideal point, not by much
    assert 0.005 < tracking["work"]["mean"] < tracking["work"]["max"] < 0.5
    assert 0.02 < tracking["supports"]["mean"] < tracking["supports"]["max"] < 1.5
    import os

    os.environ.setdefault("MAVLINK20", "1")
    from pymavlink import mavutil

    tlog = mavutil.mavlink_connection(str(tmp_path / "run" / "gcs.tlog"), dialect="ardupilotmega")
    tilts, attitudes = [], 0
    while (message := tlog.recv_match(type=["ATTITUDE", "SIM_STATE"])) is not None:
        if message.get_type() == "ATTITUDE":
            attitudes += 1
        else:
            tilts.append(max(abs(message.roll), abs(message.pitch)))
    assert attitudes >= 4 * 100  # every vehicle, every step
    assert 0.01 < max(tilts) < np.radians(35.5)  # they lean to move, within the tilt limit
    # the 3-D view draws each body's axes and the wind
    from tests.viewer.rrd import read_rrd, times

    saved = tmp_path / "run.rrd"
    assert mission("view", str(tmp_path / "run"), "--save", str(saved)).returncode == 0
    rows = read_rrd(saved)
    assert "/world/wind" in rows
    for name in ("work", "support-1", "support-2", "support-3"):
        assert len(times(rows[f"/uav/{name}/axes"])) == len(times(rows[f"/uav/{name}"])) > 100


def test_the_view_draws_the_axes_of_the_attitude_reported():
    from mission.viewer.assemble import NOSE_M, UP_M, body_axes
    from vehicle_sim.dynamics.rigid_body import rotation
    from vehicle_sim.mavlink.telemetry import Attitude

    rng = np.random.default_rng(8)
    for _ in range(10):
        q = rng.normal(size=4)
        q /= np.linalg.norm(q)
        position = rng.normal(size=3)
        nose, centre, up = body_axes(position, Attitude.of(q, np.zeros(3)).quaternion)
        turned = np.array(rotation(q), dtype=float)  # body FLU to world ENU, the simulation's
        assert centre == pytest.approx(position)
        assert nose == pytest.approx(position + NOSE_M * turned[:, 0], abs=1e-9)
        assert up == pytest.approx(position + UP_M * turned[:, 2], abs=1e-9)


def test_the_attitude_is_reported_in_mavlinks_frames():
    from scipy.spatial.transform import Rotation

    from vehicle_sim.mavlink.telemetry import Attitude

    enu_to_ned = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])
    flu_to_frd = np.diag([1.0, -1.0, -1.0])
    level = Attitude.of(np.array([1.0, 0.0, 0.0, 0.0]), np.zeros(3))
    assert level.euler == pytest.approx((0.0, 0.0, np.pi / 2))  # the nose east: yaw 90 degrees
    rng = np.random.default_rng(5)
    for _ in range(20):
        q = rng.normal(size=4)
        q /= np.linalg.norm(q)
        rates = rng.normal(size=3)
        found = Attitude.of(q, rates)
        body = Rotation.from_quat([q[1], q[2], q[3], q[0]]).as_matrix()
        ned = Rotation.from_matrix(enu_to_ned @ body @ flu_to_frd)
        yaw, pitch, roll = ned.as_euler("ZYX")
        assert found.euler == pytest.approx((roll, pitch, yaw), abs=1e-9)
        x, y, z, w = ned.as_quat()
        assert abs(np.dot(found.quaternion, (w, x, y, z))) == pytest.approx(1.0, abs=1e-9)
        assert found.rates == pytest.approx(tuple(flu_to_frd @ rates))


def test_a_hovering_quadrotor_holds_its_place_in_gusts_that_push_it():
    from dataclasses import replace

    scenario = load_scenario("along")
    # 3 m/s with its gusts: far within what its tilt limit can hold (27.4 m/s)
    gusty = replace(scenario.world.wind, speed_m_s=3.0)
    home = np.array([0.0, 12.0, 6.0])  # in the open, north of the deck
    flown = Multicopter.at(home, VEHICLE, STEP_S, gusty, [], 9)
    flown.hold()
    track = [flown.truth]
    for _ in range(120):  # a minute
        flown.step(STEP_S, 3.0, np.random.default_rng(0), 0.0)
        track.append(flown.truth)
    drift = np.linalg.norm(np.array(track) - home, axis=1)
    assert 0.02 < drift.max() < 0.5  # pushed about, never far
    again = Multicopter.at(home, VEHICLE, STEP_S, gusty, [], 9)
    again.hold()
    for _ in range(120):
        again.step(STEP_S, 3.0, np.random.default_rng(0), 0.0)
    assert np.array_equal(again.truth, track[-1])  # the same gusts for the same seed


def test_between_estimates_the_belief_drifts_as_the_filters_velocity_error_says():
    """Held still with no estimate for 10 s, the belief's error is bias x T plus a random walk
    of the per-step noise: across 150 vehicles its spread per axis is
    sqrt((sigma_b T)^2 + sigma_n^2 dt T)."""
    from vehicle_sim.dynamics.closed_loop import ClosedLoop

    loops = VEHICLE.autopilot
    loop = ClosedLoop(VEHICLE.multicopter, loops, STEP_S)
    seconds, errors = 10.0, []
    for seed in range(150):
        body = Multicopter(loop, np.array([0.0, 12.0, 6.0]), None, np.random.default_rng(seed))
        body.hold()
        for _ in range(round(seconds / STEP_S)):
            body.step(STEP_S, 3.0, np.random.default_rng(0), 0.0)
        errors.append(body.believed - body.truth)
    spread = np.std(np.array(errors), axis=0)
    expected = np.hypot(
        loops.velocity_bias_m_s * seconds, loops.velocity_noise_m_s * np.sqrt(STEP_S * seconds)
    )
    assert spread == pytest.approx(np.full(3, expected), rel=0.2)
    estimate = Multicopter.at(np.zeros(3) + 6, VEHICLE, STEP_S, drift_rng=np.random.default_rng(1))
    estimate.set_estimate(estimate.truth)
    assert estimate.believed == pytest.approx(estimate.truth)  # an estimate resets it

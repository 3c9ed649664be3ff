"""Time: lockstep is deterministic for a seed; real time follows the speed-up."""

from __future__ import annotations

import time

import pytest

from tests.mav_client import MavClient
from tests.processes import vehicle_process

pytestmark = pytest.mark.slow  # every test here starts processes

SENSOR_TYPES = {"GPS_RAW_INT", "LANDING_TARGET", "SIM_STATE"}


def _sensor_packets(seed: int) -> list[tuple[int, bytes]]:
    """Payloads of the sensor messages, per vehicle in order (vehicles interleave freely)."""
    with (
        vehicle_process("support-2", "--seed", str(seed)) as s2,
        vehicle_process(
            "work",
            "--seed",
            str(seed),
            "--truth-out",
            f"127.0.0.1:{s2.truth_port}",
            home=(0.0, 0.0, 6.0),
        ) as work,
    ):
        client = MavClient(work.address, s2.address)
        client.arm_guided(1, to=work.address)
        packets = []
        for k in range(1, 41):
            client.setpoint(1, [0.05 * k, 0.0, 6.0], to=work.address)
            packets += [
                (m.get_srcSystem(), bytes(m.get_msgbuf()[10:-2]))
                for m in client.step_to(500 * k)
                if m.get_type() in SENSOR_TYPES
            ]
        client.close()
    return sorted(packets, key=lambda p: p[0])  # stable: keeps each vehicle's own order


def test_lockstep_is_deterministic_for_a_seed():
    first, again, other = _sensor_packets(3), _sensor_packets(3), _sensor_packets(4)
    assert len(first) == 40 * 2 + 40 * 2 + 40  # GPS x2, SIM_STATE x2, LANDING_TARGET x1
    assert first == again
    assert first != other


@pytest.mark.parametrize("speedup", [4.0])
def test_real_time_mode_follows_the_speedup(speedup):
    with vehicle_process("support-1", "--speedup", str(speedup)) as vehicle:
        client = MavClient(vehicle.address)
        client.send(client_heartbeat())
        first = client.wait_for("SYSTEM_TIME", 5.0)
        start = time.monotonic()
        time.sleep(3.0)
        client.queue._pending.clear()
        client.endpoint.receive()
        latest = client.wait_for("SYSTEM_TIME", 5.0)
        elapsed = time.monotonic() - start
        client.close()
    simulated = (latest.time_boot_ms - first.time_boot_ms) / 1000.0
    assert simulated == pytest.approx(elapsed * speedup, abs=1.5)


def client_heartbeat():
    """A ground station's HEARTBEAT (makes the vehicle add us as a peer)."""
    from pymavlink.dialects.v20 import ardupilotmega as mavlink2

    return mavlink2.MAVLink_heartbeat_message(
        mavlink2.MAV_TYPE_GCS, mavlink2.MAV_AUTOPILOT_INVALID, 0, 0, 0, 3
    )


def test_a_waiting_vehicle_answers_a_new_peer_at_once():
    """Before the first tick a vehicle beats once a second; a new ground station does not wait
    for the next beat (the first client's beat fixes the phase: the next is ~1 s away)."""
    with vehicle_process("support-1") as vehicle:
        first = MavClient(vehicle.address)
        first.send(client_heartbeat())
        assert first.wait_for("HEARTBEAT", 3.0) is not None
        second = MavClient(vehicle.address, system_id=254)
        sent = time.monotonic()
        second.send(client_heartbeat())
        answer = second.wait_for("HEARTBEAT", 3.0)
        waited = time.monotonic() - sent
        first.close()
        second.close()
    assert answer is not None
    assert waited < 0.3


def _short_waits(tmp_path, timeout_s: float):
    """Along with the truth waited for ``timeout_s`` (the default's 10 s would make the test
    wait that long)."""
    path = tmp_path / "short-waits.yaml"
    path.write_text(f"extends: along\nvehicle: {{truth_timeout_wall_s: {timeout_s}}}\n")
    return path


def test_a_support_waits_for_the_work_uavs_truth_of_the_step_up_to_the_timeout(tmp_path):
    """In lockstep a support publishes a step once the work UAV's truth of that step is there:
    late truth is waited for; missing truth, for ``vehicle.truth_timeout_wall_s`` (here 2 s), after
    which the camera sees the last known position (counted as an extrapolated truth).
    Truth samples are keyed by simulated microseconds in lockstep."""
    import numpy as np

    from vehicle_sim.process.truth_link import TruthSender

    timeout = 2.0
    with vehicle_process("support-1", scenario=str(_short_waits(tmp_path, timeout))) as support:
        assert support.truth_port is not None
        truth = TruthSender(1, [("127.0.0.1", support.truth_port)])
        client = MavClient(support.address)
        work = np.array([0.0, -4.0, 7.0])
        truth.publish(work, 500_000)
        on_time = _step_marker_after(client, 500)
        assert on_time < 0.5 * timeout
        client.send(mavlink2_tick(1000))
        time.sleep(0.3)
        truth.publish(work, 1_000_000)  # late, but within the timeout
        late = _wait_marker(client, 1000, time.monotonic() - 0.3)
        assert 0.3 <= late < 0.3 + 0.5 * timeout
        missing = _step_marker_after(client, 1500)  # no truth at all
        assert timeout <= missing < timeout + 1.0
        targets = [m for m in client.seen if m.get_type() == "LANDING_TARGET"]
        assert len(targets) == 3 and all(t.position_valid for t in targets)
        truth.close()
        client.close()
        report = support.stop()
    assert "truth waits timed out 1, truth interpolated 0, extrapolated 1" in report


def test_a_support_does_not_wait_for_a_truth_older_than_one_it_has(tmp_path):
    """Truth samples come in order: once a later one is there, the truth of the step was lost
    or came before the support listened (a support restarted into a running mission), and
    waiting for it would only stall the support for the timeout at every such step."""
    import numpy as np

    from vehicle_sim.process.truth_link import TruthSender

    timeout = 2.0
    with vehicle_process("support-1", scenario=str(_short_waits(tmp_path, timeout))) as support:
        assert support.truth_port is not None
        truth = TruthSender(1, [("127.0.0.1", support.truth_port)])
        client = MavClient(support.address)
        truth.publish(
            np.array([0.0, -4.0, 7.0]), 1_000_000
        )  # the next step's truth, not this one's
        time.sleep(0.3)  # it has arrived
        assert _step_marker_after(client, 500) < 0.5 * timeout
        assert _step_marker_after(client, 1000) < 0.5 * timeout  # its own truth: no wait either
        truth.close()
        client.close()
        report = support.stop()
    assert "truth waits timed out 0, truth interpolated 0, extrapolated 1" in report


def mavlink2_tick(time_ms: int):
    """The ground station's lockstep tick to ``time_ms``."""
    from pymavlink.dialects.v20 import ardupilotmega as mavlink2

    return mavlink2.MAVLink_system_time_message(0, time_ms)


def _step_marker_after(client: MavClient, time_ms: int) -> float:
    """Tick to ``time_ms``; seconds until the vehicle's step marker for it arrives."""
    sent = time.monotonic()
    client.send(mavlink2_tick(time_ms))
    return _wait_marker(client, time_ms, sent)


def _wait_marker(client: MavClient, time_ms: int, since: float) -> float:
    marker = client.wait_for("SYSTEM_TIME", 5.0, lambda m: m.time_boot_ms == time_ms)
    assert marker is not None, f"no step marker for {time_ms} ms"
    return time.monotonic() - since


def test_in_real_time_a_support_interpolates_the_truth_and_answers_timesync_at_once():
    """Real time: the work UAV's truth arrives keyed by the host's wall clock at its steps,
    out of phase with the support's; the support waits for the sample after its own step
    and interpolates (extrapolates only once the truth stops coming). TIMESYNC is answered
    with the vehicle's clock at the instant of the reply, not at its last step."""
    import numpy as np
    from pymavlink.dialects.v20 import ardupilotmega as mavlink2

    from vehicle_sim.process.truth_link import TruthSender

    with vehicle_process("support-1", "--speedup", "10") as support:
        assert support.truth_port is not None
        truth = TruthSender(1, [("127.0.0.1", support.truth_port)])
        client = MavClient(support.address)
        answers = []
        start = time.monotonic()
        sample = 0
        while time.monotonic() - start < 2.0:
            wall = time.time()
            truth.publish(np.array([0.1 * sample, -4.0, 7.0]), round(wall * 1e6))
            sample += 1
            if sample % 10 == 5:  # every 0.37 s: a TIMESYNC request (ts1: our wall ns)
                client.send(mavlink2.MAVLink_timesync_message(0, time.monotonic_ns()))
            time.sleep(0.037)  # the work UAV's steps, not the support's (0.05 s)
        answers = [m for m in client.collect(0.3) + client.seen if m.get_type() == "TIMESYNC"]
        truth.close()
        client.close()
        report = support.stop()
    counts = {
        name: int(report.split(f"{name} ")[1].split(",")[0])
        for name in ("truth waits timed out", "truth interpolated", "extrapolated")
    }
    assert counts["truth interpolated"] >= 30
    # extrapolated only after the truth stopped coming (the steps while we stopped)
    assert counts["extrapolated"] == counts["truth waits timed out"] <= 10
    by_request = {m.ts1: m.tc1 for m in answers}
    assert len(by_request) >= 3
    sent, clock = (
        np.array(sorted(by_request)),
        np.array([by_request[k] for k in sorted(by_request)]),
    )
    # the vehicle's clock runs 10x the wall clock, continuously (not in 0.5 s steps)
    rates = np.diff(clock) / np.diff(sent)
    np.testing.assert_allclose(rates, 10.0, rtol=0.1)
    assert np.any((clock / 1e9) % 0.5 > 0.05)


def test_after_a_wait_that_timed_out_a_silent_work_uav_is_not_waited_for_again(tmp_path):
    """A frozen work UAV: the first step waits the timeout, the next ones do not, until a
    truth arrives again."""
    import numpy as np

    from vehicle_sim.process.truth_link import TruthSender

    timeout = 1.0
    with vehicle_process("support-1", scenario=str(_short_waits(tmp_path, timeout))) as support:
        truth = TruthSender(1, [("127.0.0.1", support.truth_port)])
        client = MavClient(support.address)
        work = np.array([0.0, -4.0, 7.0])
        truth.publish(work, 500_000)
        assert _step_marker_after(client, 500) < 0.5 * timeout
        assert timeout <= _step_marker_after(client, 1000) < timeout + 1.0  # waited, in vain
        assert _step_marker_after(client, 1500) < 0.5 * timeout  # not again
        truth.publish(work, 2_000_000)  # heard from again
        assert _step_marker_after(client, 2000) < 0.5 * timeout  # its own truth: no wait
        assert timeout <= _step_marker_after(client, 2500) < timeout + 1.0  # waited again
        truth.close()
        client.close()
        report = support.stop()
    assert "truth waits timed out 2" in report

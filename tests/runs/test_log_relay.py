"""`mission run` shows what the ground station says of a first run's compilation, and stops a
run that makes no progress."""

from __future__ import annotations

import subprocess
import sys
import time

import pytest

from ground_station.support_mpc import nlp_cache
from mission.runs.compile_relay import CompileRelay, compile_summary

STARTED = "compiling the support MPC (support_mpc_near, support_mpc_far) with gcc: once per machine"
DONE = "compiled the support MPC (support_mpc_near, support_mpc_far) in 9.5 s"


def test_the_relay_knows_the_ground_stations_own_words(tmp_path, capsys):
    log = tmp_path / "ground_station.log"
    log.write_text("")
    nlp_cache.SUPPORT_MPC.started(["margin_half_spaces"], "gcc", "/cache")
    nlp_cache.SUPPORT_MPC.finished(["margin_half_spaces"], 2.31)
    log.write_text(capsys.readouterr().err)
    relay = CompileRelay(log)
    relay.poll()
    assert capsys.readouterr().err.splitlines() == [
        "compiling the support MPC (margin_half_spaces) with gcc: once per machine, "
        "cached in /cache",
        "compiled the support MPC (margin_half_spaces) in 2.3 s",
    ]
    assert compile_summary(log) == {"the support MPC (margin_half_spaces)": 2.3}


def test_every_compile_line_is_shown_when_whole_and_counted_until_done(tmp_path, capsys):
    log = tmp_path / "ground_station.log"
    log.write_text("ground station listening on 127.0.0.1:5\n")
    relay = CompileRelay(log)
    relay.poll()
    assert capsys.readouterr().err == "" and not relay.compiling
    with log.open("a") as handle:
        handle.write(f"ground station: {STARTED}\n")
        handle.write("ground station: compiled the support MPC (margin_half_spaces) in 2.0 s\n")
        handle.write(f"ground station: {STARTED}\n")
        handle.write(f"ground station: {DONE[:-5]}")  # not a whole line yet
    relay.poll()
    assert capsys.readouterr().err.splitlines() == [
        STARTED,
        "compiled the support MPC (margin_half_spaces) in 2.0 s",
        STARTED,
    ]
    assert relay.compiling
    with log.open("a") as handle:
        handle.write(DONE[-5:] + "\n")
    relay.poll()
    relay.poll()
    assert capsys.readouterr().err == f"{DONE}\n" and not relay.compiling


def test_a_missing_log_is_no_news(tmp_path, capsys):
    CompileRelay(tmp_path / "none.log").poll()
    assert capsys.readouterr().err == ""


def test_a_first_runs_compilations_are_read_from_the_ground_stations_log(tmp_path):
    log = tmp_path / "ground_station.log"
    log.write_text(
        "ground station listening on 127.0.0.1:5000\n"
        "ground station: compiling the support MPC (margin_half_spaces) with gcc: once, cached\n"
        "ground station: compiled the support MPC (margin_half_spaces) in 2.3 s\n"
        f"ground station: {STARTED}, cached\n"
        "ground station: compiled the support MPC (support_mpc_near, support_mpc_far) in 26.3 s\n"
    )
    assert compile_summary(log) == {  # each left out of the run's real-time factor
        "the support MPC (margin_half_spaces)": 2.3,
        "the support MPC (support_mpc_near, support_mpc_far)": 26.3,
    }
    log.write_text("ground station listening on 127.0.0.1:5000\n")
    assert compile_summary(log) == {} and compile_summary(tmp_path / "none.log") == {}


def test_a_tlog_that_stops_growing_stalls_unless_the_mpc_is_compiling(tmp_path):
    from mission.runs.stall import StallWatch

    now = [100.0]
    tlog = tmp_path / "gcs.tlog"
    watch = StallWatch(tlog, 30.0, clock=lambda: now[0])
    now[0] += 29.0
    assert not watch.stalled()  # no tlog yet: start-up, 29 s
    now[0] += 1.0
    assert watch.stalled()  # still none after 30 s
    tlog.write_bytes(b"x")
    assert not watch.stalled()  # it grew: the wait starts again
    now[0] += 40.0
    assert not watch.stalled(paused=True)  # compiling: not a stall, and it restarts the wait
    now[0] += 29.9
    assert not watch.stalled()
    now[0] += 0.1
    assert watch.stalled()
    assert not StallWatch(tlog, 0.0, clock=lambda: now[0] + 1e9).stalled()  # 0: never


@pytest.mark.slow
def test_a_ground_station_that_hangs_is_stopped_as_stalled(tmp_path):
    """A real process that never logs: the supervision gives up after the limit."""
    from mission.procs.interrupts import StopRequest
    from mission.runs.orchestrator import Child, RunFailed, _supervise
    from mission.runs.stall import StallWatch

    log = tmp_path / "ground_station.log"
    log.write_text("ground station listening on 127.0.0.1:5\nground station: cycle 3\n")
    hung = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        gcs = Child("ground_station", hung, log)
        started = time.monotonic()
        with StopRequest() as stop, pytest.raises(RunFailed) as failure:
            _supervise(gcs, [gcs], {"work"}, None, stop, StallWatch(tmp_path / "gcs.tlog", 1.0))
        assert 1.0 <= time.monotonic() - started < 30
        assert str(failure.value).startswith("stalled: gcs.tlog did not grow for 1 s")
        assert "cycle 3" in str(failure.value)  # the ground station's last word
        assert hung.poll() is None  # stopping it is the run's (run_mission's finally)
    finally:
        hung.kill()
        hung.wait()

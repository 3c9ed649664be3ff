"""The profile report attributes py-spy's samples to the right processes and phases."""

from __future__ import annotations

from mission.bench.profile import read_profile, report

RUN = 'process 10:"python -m mission run"'
ORCHESTRATOR = "run_mission (mission/runs/orchestrator.py:90)"
FORK = ("_start_processes (mission/runs/orchestrator.py:200)", "_child (forked.py:150)")
GCS = ('process 11:"python -m mission run"', "entry_point (ground_station/cli.py:9)")
HELPER = ('process 12:"x"', "serve_descriptors (ground_station/support_mpc/helper.py:7)")
VEHICLE = "entry_point (vehicle_sim/cli.py:5)"


def _line(*frames: str, count: int) -> str:
    """One collapsed stack, as py-spy's raw format writes it."""
    return ";".join((RUN, ORCHESTRATOR, *frames)) + f" {count}"


RECORDING = [
    _line("_summary (mission/runs/orchestrator.py:300)", "decode (x.py:5)", count=30),
    _line(FORK[0], "_find_and_load (<frozen importlib._bootstrap>:1)", count=5),
    _line("wait (mission/procs/forked.py:70)", count=2),
    _line(*FORK, *GCS, "solve (casadi:1)", count=40),
    _line(*FORK, *GCS, "start (g.py:3)", *HELPER, "solve (casadi:1)", count=10),
    _line(*FORK, 'process 13:"y"', VEHICLE, "_serve (vehicle_sim/server.py:150)", count=6),
    _line(*FORK, 'process 14:"y"', VEHICLE, "_transmit (mavlink_udp.py:130)", count=7),
    _line(*FORK, 'process 14:"y"', VEHICLE, "_serve (vehicle_sim/server.py:151)", count=1),
]


def test_samples_go_to_the_last_process_on_their_stack_and_its_role():
    profile = read_profile(RECORDING)
    assert dict(profile.samples) == {
        "orchestrator: analysis": 30,
        "orchestrator: start-up": 5,
        "orchestrator: the run": 2,
        "ground station": 40,
        "mpc helper": 10,
        "vehicle": 14,
    }
    assert profile.processes["vehicle"] == {"13", "14"}
    assert profile.own["vehicle"]["_serve (vehicle_sim/server.py)"] == 7  # lines merged
    text = report(profile, rate_hz=10.0)
    assert "| ground station | 1 | 4.00 | 39.6 % |" in text
    assert "| all | | 10.10 | 100 % |" in text

"""A run's lockstep integrity from its vehicles' logs and the station's link statistics."""

from __future__ import annotations

from mission.analysis.lockstep import integrity_note, lockstep_integrity

LINE = (
    "{name}: 515 steps to t=257.5 s; link in 1565 packets / 536 datagrams, bad 0 datagrams "
    "(0 packets), out 3915, rejected: none; vehicle rejected: none; auto steps {auto}, truth "
    "waits timed out {waits}, truth interpolated 0, extrapolated 0, steps resent 0\n"
)


def _logs(tmp_path, counts):
    logs = {}
    for name, (auto, waits) in counts.items():
        logs[name] = tmp_path / f"{name}.log"
        logs[name].write_text("starting\n" + LINE.format(name=name, auto=auto, waits=waits))
    return logs


def test_a_run_with_no_timeout_is_exact_and_says_nothing(tmp_path):
    logs = _logs(tmp_path, {"work": (0, 0), "support-1": (0, 0)})
    integrity = lockstep_integrity(logs, {"late_steps": 0})
    assert integrity == {
        "exact": True,
        "auto_steps": 0,
        "truth_waits_timed_out": 0,
        "late_steps": 0,
    }
    assert integrity_note({"lockstep": integrity}) == ""


def test_every_count_is_summed_and_named(tmp_path):
    logs = _logs(tmp_path, {"work": (2, 0), "support-1": (1, 3)})
    integrity = lockstep_integrity(logs, {"late_steps": 4})
    assert (integrity["auto_steps"], integrity["truth_waits_timed_out"]) == (3, 3)
    assert not integrity["exact"] and integrity["late_steps"] == 4
    note = integrity_note({"lockstep": integrity})
    assert note == (
        "; NOT exact lockstep (auto steps 3, truth waits timed out 3, late steps 4): "
        "it may not reproduce"
    )


def test_a_vehicle_whose_counts_are_missing_is_not_taken_for_exact(tmp_path):
    logs = _logs(tmp_path, {"work": (0, 0)})
    logs["support-1"] = tmp_path / "cut.log"
    logs["support-1"].write_text("starting\n")  # killed before its last line
    integrity = lockstep_integrity(logs, None)
    assert not integrity["exact"] and integrity["unread_vehicles"] == ["support-1"]
    assert "no counts from support-1" in integrity_note({"lockstep": integrity})

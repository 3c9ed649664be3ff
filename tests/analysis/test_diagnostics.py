"""The diagnostics of summary.json against a hand count on a small made-up run."""

from __future__ import annotations

import numpy as np
import pytest

from mission.analysis.diagnostics import diagnostics
from mission.analysis.metrics import RunTrace
from mission.link.plan_files import read_vehicle_waypoints

IN_ZONE = np.array([-5.0, 6.5, 8.5])  # inside Along's zone
OPEN = np.array([-5.0, 12.0, 8.5])


def _trace(along) -> tuple[RunTrace, list[dict]]:
    trace = RunTrace()
    records = []
    for k in range(1, 7):
        t = 0.5 * k
        work = np.array([-12.0, -3.0 + 0.1 * k, 7.0])
        trace.truth[(1, t)] = work
        trace.truth[(2, t)] = IN_ZONE if k in (2, 3, 4) else OPEN  # support-1
        trace.truth[(3, t)] = IN_ZONE if k == 6 else OPEN  # support-2
        trace.truth[(4, t)] = OPEN
        trace.ticks.add(t)
        trace.cycles.add(t)  # the work UAV's setpoint of cycle k
        trace.estimates[t] = work + [0.1 * k, 0.0, 0.0]  # error 0.1 k
        consistent = ["support-1", "support-2", "support-3"] if k in (3, 6) else ["support-2"]
        records.append({"t": t, "consistent": consistent, "fallback": k == 3, "blind": False})
    trace.completion = 300.0
    return trace, records


def test_diagnostics_count_as_a_hand_count_does(along, along_world):
    trace, records = _trace(along)
    found = diagnostics(trace, records, along_world, along)
    assert found["supports"] == {
        "support-1": {"zone_cycles": 3, "fused_in_zone": 1, "fused_in_zone_rate": 0.3333},
        "support-2": {"zone_cycles": 1, "fused_in_zone": 1, "fused_in_zone_rate": 1.0},
        "support-3": {"zone_cycles": 0, "fused_in_zone": 0, "fused_in_zone_rate": None},
    }
    assert found["empty_s_cycles"] == 1 and found["blind_cycles"] == 0
    # some support in a zone at k = 2, 3, 4, 6: errors 0.2, 0.3, 0.4, 0.6; none at k = 1, 5
    assert found["work_error_mean_m_support_in_zone"] == pytest.approx(0.375)
    assert found["work_error_mean_m_none_in_zone"] == pytest.approx(0.3)
    path = np.vstack([trace.truth[(1, 0.5)], read_vehicle_waypoints(along, "work")])
    flight = np.sum(np.linalg.norm(np.diff(path, axis=0), axis=1)) / 0.3
    assert found["time_beyond_flight_s"] == pytest.approx(300.0 - flight, abs=1e-3)
    trace.completion = None
    assert diagnostics(trace, records, along_world, along)["time_beyond_flight_s"] is None


def test_contacts_are_listed_by_time_then_reporter_whatever_order_they_came_in(along, along_world):
    from mission.analysis.safety import safety_metrics

    trace, _ = _trace(along)
    touch = {"at_m": [-5.0, 12.0, 8.5], "crash": False}
    trace.contacts = [  # as a tlog may hold them: two vehicles' reports of one touch interleave
        {"t": 2.0, "vehicle": "support-2", "with": "support-1", **touch},
        {"t": 1.5, "vehicle": "support-3", "with": "structure", **touch},
        {"t": 2.0, "vehicle": "support-1", "with": "support-2", **touch},
    ]
    listed = [(c["t"], c["vehicle"]) for c in safety_metrics(trace, along_world)["contacts"]]
    assert listed == [(1.5, "support-3"), (2.0, "support-1"), (2.0, "support-2")]

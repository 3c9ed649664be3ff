"""An exclusion judged against the truth: false where no lying fault and no multipath bias,
a biased fix's where a zone held the support or, with multipath from geometry, its fix was
truly off by more than the motion test's detectable bias."""

from __future__ import annotations

import numpy as np
import pytest

from mission.analysis.gnss_errors import detectable_bias_m
from mission.analysis.integrity import integrity_metrics
from mission.analysis.trace import RunTrace
from mission.config.scenario import load_scenario
from mission.world.model import World

SUPPORT = 2  # support-1's system id
AT = np.array([0.0, -10.0, 8.0])  # in the open, beside the deck


def _trace(fix_errors_m: dict[float, float], late_s: float = 0.0) -> RunTrace:
    """Truth every 0.5 s; a fix of support-1 every 0.5 s, ``late_s`` before the cycle's time
    (a real-time receiver's clock), off by ``fix_errors_m`` at the cycles named."""
    trace = RunTrace(max_gap_s=1.0)
    for t in np.arange(0.0, 5.5, 0.5):
        t = round(float(t), 3)
        for system in (1, SUPPORT):
            trace.truth[(system, t)] = AT + [0.0, 0.0, -2.0 * (system == 1)]
        fix_t = round(t - late_s, 4)
        trace.fixes[(SUPPORT, fix_t)] = AT + [fix_errors_m.get(t, 0.05), 0.0, 0.0]
    return trace


def _records(excluded_at: list[float]) -> list[dict]:
    records = []
    for t in np.arange(0.5, 5.5, 0.5):
        t = round(float(t), 3)
        events = [{"kind": "excluded", "support": "support-1"}] if t in excluded_at else []
        verdict = {"excluded": [], "withheld": [], "ambiguous": False, "events": events}
        records.append({"t": t, "integrity": verdict})
    return records


@pytest.mark.parametrize("late_s", [0.0, 0.0371])  # lockstep; a real-time receiver's time
def test_a_geometry_exclusion_of_a_truly_biased_fix_is_no_false_alarm(late_s):
    world = World(load_scenario("river", {"integrity.enabled": True}))
    bias = detectable_bias_m(world)
    trace = _trace({1.0: 3.0 * bias, 2.0: 0.5 * bias}, late_s)
    block = integrity_metrics(trace, _records([1.0, 2.0, 3.0]), world, [])
    # 1.0 s: off by 3 MDBs (a real bias); 2.0 s: half of one; 3.0 s: 5 cm (nothing)
    assert (block["zone_exclusions"], block["false_alarms"]) == (1, 2)


def test_with_zones_alone_a_fix_error_does_not_excuse_an_exclusion():
    world = World(load_scenario("along", {"integrity.enabled": True}))
    trace = _trace({1.0: 10.0})  # a lie the zones did not make: judged by the zones only
    block = integrity_metrics(trace, _records([1.0]), world, [])
    assert (block["zone_exclusions"], block["false_alarms"]) == (0, 1)

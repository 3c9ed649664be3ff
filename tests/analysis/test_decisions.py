"""The digest of a run's decisions: blind to the last bits of a number and to wall-clock
fields, and to nothing a decision is made of."""

from __future__ import annotations

import copy

import pytest

from mission.analysis.decisions import decisions_digest


def _record() -> dict:
    return {
        "t": 0.5,
        "k": 1,
        "xhat": [-11.9395, -3.11, 6.9694],
        "blind": False,
        "fallback": False,
        "consistent": ["support-1", "support-2"],
        "contributing": ["support-1", "support-2", "support-3"],
        "yhat": {"support-1": [-7.7596, 6.6903, 7.4371]},
        "beta": {"support-1": 1.0, "support-2": 0.9999975716382984, "support-3": 0.6175536605},
        "arrived": None,
        "g_updated_voxels": 81,
        "mpc": {
            "support-1": {
                "status": "SOLVER_RET_SUCCESS",
                "ms": 7.03,
                "resolved": True,
                "path": [[-7.4733, 6.25, 7.9021], [-7.139, 6.25, 0.0]],
            }
        },
        "cycle_ms": 13.388,
    }


def _changed(change) -> str:
    record = copy.deepcopy(_record())
    change(record)
    return decisions_digest([record])


BASE = decisions_digest([_record()])


def test_the_last_bits_and_the_wall_clock_do_not_count():
    def last_bits(r):
        r["beta"]["support-2"] += 4.4e-16  # AVX2 against AVX-512 kernels
        r["beta"]["support-3"] -= 5e-16

    assert _changed(last_bits) == BASE
    assert _changed(lambda r: r.update(cycle_ms=99.0, age_ms={"support-1": [100, 90]})) == BASE
    assert _changed(lambda r: r["mpc"]["support-1"].update(ms=0.5)) == BASE
    assert _changed(lambda r: r["mpc"]["support-1"]["path"][1].__setitem__(2, -0.0)) == BASE


@pytest.mark.parametrize(
    "change",
    [
        lambda r: r["beta"].__setitem__("support-3", 0.6175546605),  # 1e-6
        lambda r: r["xhat"].__setitem__(0, -11.9396),  # 0.1 mm
        lambda r: r["mpc"]["support-1"]["path"][0].__setitem__(1, 6.2501),
        lambda r: r.update(consistent=["support-1"]),
        lambda r: r["mpc"]["support-1"].update(resolved=False),
        lambda r: r["mpc"]["support-1"].update(status="SOLVER_RET_MAXITER"),
        lambda r: r.update(g_updated_voxels=80),
        lambda r: r.update(roles={"support-1": "inspecting"}),
    ],
)
def test_a_decision_that_moves_moves_the_digest(change):
    assert _changed(change) != BASE


def test_the_order_and_number_of_cycles_count():
    second = _record() | {"t": 1.0}
    assert decisions_digest([_record(), second]) != decisions_digest([second, _record()])
    assert decisions_digest([_record(), second]) != BASE
    assert len(BASE) == 16

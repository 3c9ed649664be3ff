"""The parameter catalogue: what a set may be, and the docs listing every parameter."""

from __future__ import annotations

import math

import pytest

from mission.config.vehicle_parameters import PARAMETERS, live_parameter_names, parameter_spec
from tests.processes import ROOT


def test_docs_list_every_parameter_of_the_catalogue():
    text = (ROOT / "docs" / "vehicle.md").read_text()
    missing = [spec.name for spec in PARAMETERS if f"`{spec.name}`" not in text]
    assert not missing, f"docs/vehicle.md does not list {missing}"


@pytest.mark.parametrize(
    ("name", "value", "reason"),
    [
        ("SIM_GPS1_ENABLE", 0.5, "needs a whole number"),
        ("SIM_GPS1_ENABLE", 2, "must be in [0, 1]"),
        ("SIM_MP_SCALE", math.nan, "needs a finite value"),
        ("SIM_RADIUS", 0.3, "fixed for the run"),
        ("SIM_SPEEDUP", 2, "the run's clock"),
        ("SIM_GPS_UERE", 0.5, None),
    ],
)
def test_a_value_is_refused_with_the_reason(name, value, reason):
    refusal = parameter_spec(name).refusal(value)
    assert refusal == reason if reason is None else reason in refusal


def test_ids_are_unique_and_the_live_ones_listed():
    names = [spec.name for spec in PARAMETERS]
    assert len(set(names)) == len(names)
    assert "SIM_SPEEDUP" not in live_parameter_names()
    assert "SIM_GPS1_GLTCH_X" in live_parameter_names()
    assert parameter_spec("NO_SUCH") is None

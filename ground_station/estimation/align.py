"""Measurements brought to the cycle's time (real time).

A support's GNSS fix p_n and camera observation r_n are taken at its own steps, which in real
time fall between the ground station's cycles: at a cycle's time they are ``age`` seconds old.
Over that time each vehicle moved, as far as the ground station knows, along the displacement
it was last commanded (the step ending at this cycle), so

    p_n(t) = p_n(t - a_p) + a_p / t_cont * d_n
    r_n(t) = r_n(t - a_r) + a_r / t_cont * (d_work - d_n)

with d_n and d_work the supports' and the work UAV's last commanded displacements. Then
mu_n = p_n + r_n describes the work UAV at the cycle's time. A measurement of age zero (every
one in lockstep) is used as it is.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from ground_station.estimation.localize import SupportReport
from ground_station.state.station_state import StationState


def align(
    reports: Sequence[SupportReport], state: StationState, step_s: float
) -> list[SupportReport]:
    """Each report with its measurements propagated to the cycle's time."""
    return [_aligned(report, state, step_s) for report in reports]


def _aligned(report: SupportReport, state: StationState, step_s: float) -> SupportReport:
    if report.fix_age_s == 0.0 and report.relative_age_s == 0.0:
        return report
    support_velocity = state.last_support_command.get(report.name, np.zeros(3)) / step_s
    work_velocity = state.last_work_command / step_s
    fix, relative = report.fix, report.relative
    if fix is not None and report.fix_age_s != 0.0:
        fix = fix + support_velocity * report.fix_age_s
    if relative is not None and report.relative_age_s != 0.0:
        relative = relative + (work_velocity - support_velocity) * report.relative_age_s
    return replace(report, fix=fix, relative=relative)

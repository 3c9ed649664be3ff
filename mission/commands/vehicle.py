"""``mission vehicle``: how a scenario's quadrotor flies with its autopilot's gains: its step
and gust responses beside the linear design of PX4's cascade with the same gains, in numbers
and a figure."""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

from mission.commands.common import add_scenario_argument, check_figure_path

TICK_S = 0.02
BAND_M = 0.02


def add_parser(commands) -> None:
    """``mission vehicle``'s arguments."""
    parser = commands.add_parser(
        "vehicle", help="a scenario's quadrotor: its step and gust responses with its gains"
    )
    add_scenario_argument(parser)
    parser.add_argument(
        "--plot",
        type=Path,
        metavar="FILE.png|pdf|svg",
        help="draw the responses beside the linear design of PX4's cascade",
    )
    parser.set_defaults(handler=vehicle)


def _finite(seconds: float) -> float | None:
    """A time for JSON: rounded, or None where it never settles (inf is not JSON)."""
    return None if math.isinf(seconds) else round(seconds, 2)


def vehicle(args: argparse.Namespace) -> int:
    """``mission vehicle``: the responses' numbers as one JSON object, and the figure."""
    if args.plot is not None:
        check_figure_path(args.plot, "--plot")
    from mission.config.scenario import load_scenario
    from vehicle_sim.dynamics.closed_loop import ClosedLoop
    from vehicle_sim.dynamics.responses import gust_response, settling_s, step_response

    scenario = load_scenario(args.scenario)
    body, loops = scenario.vehicle.multicopter, scenario.vehicle.autopilot
    loop = ClosedLoop(body, loops, TICK_S)
    step, gust = step_response(loop), gust_response(loop)
    numbers = {
        "step_overshoot_m": {
            "model": round(float(step.model_m.max()) - 1.0, 4),
            "design": round(float(step.design_m.max()) - 1.0, 4),
        },
        "step_settling_2cm_s": {
            "model": _finite(settling_s(step.times_s, step.model_m, 1.0, BAND_M)),
            "design": _finite(settling_s(step.times_s, step.design_m, 1.0, BAND_M)),
        },
        "step_tilt_max_deg": round(float(step.tilt_deg.max()), 2),
        "gust_displacement_max_m": {
            "model": round(float(gust.model_m.max()), 4),
            "design": round(float(gust.design_m.max()), 4),
        },
        "gust_settling_2cm_s": {
            "model": _finite(settling_s(gust.times_s, gust.model_m, 0.0, BAND_M)),
            "design": _finite(settling_s(gust.times_s, gust.design_m, 0.0, BAND_M)),
        },
    }
    json.dump(numbers, sys.stdout)
    sys.stdout.write("\n")
    if args.plot is not None:
        from mission.analysis.response_plot import plot_responses

        gains = (
            f"MPC_XY_P {loops.position_gain_per_s:g}, MPC_XY_VEL_P/I/D_ACC "
            f"{loops.velocity_gain_per_s:g}/{loops.velocity_integral_gain_per_s2:g}/"
            f"{loops.velocity_derivative_gain:g}"
        )
        plot_responses(step, gust, f"{scenario.name}: the quadrotor with {gains}", args.plot)
    return 0

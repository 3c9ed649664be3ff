"""The figure of ``mission vehicle``: a flown quadrotor's step and gust responses beside the
linear design of its cascade (computed by :mod:`vehicle_sim.dynamics.responses`)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt

from mission.analysis.figures import save_figure


def plot_responses(step: Any, gust: Any, title: str, path: Path) -> None:
    """Two panels: the position step, the steady wind from 1 s on; each the model's
    displacement and the design's."""
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2), constrained_layout=True)
    panels = (
        (left, step, "a 1 m position step", "x (m)"),
        (right, gust, "a steady 3 m/s wind from 1 s on, holding", "displacement downwind (m)"),
    )
    for axes, response, what, label in panels:
        axes.plot(response.times_s, response.model_m, label="the model (rigid body, autopilot)")
        axes.plot(response.times_s, response.design_m, "--", label="PX4's cascade, linear design")
        axes.set_title(what)
        axes.set_xlabel("time (s)")
        axes.set_ylabel(label)
        axes.grid(alpha=0.3)
        axes.legend(loc="lower right" if axes is left else "upper right")
    fig.suptitle(title)
    save_figure(fig, path)

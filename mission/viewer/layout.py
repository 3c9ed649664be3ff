"""The layout the viewer opens on (Rerun's blueprint API): the formation in 3-D, a top view
that keeps every track so far, and the timeline plots."""

from __future__ import annotations

import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from mission.viewer import frame as f
from mission.viewer.scene import Scene

# the top view leaves the structure out: the work UAV flies under the deck
TRACKED = ["+ /world/**", "- /world/structure", "+ /plan/**", "+ /uav/**", "+ /estimate/**"]
TRACKED += ["+ /gnss/**"]


def blueprint(scene: Scene) -> rrb.Blueprint:
    """Left: the 3-D view (what is at the time cursor: positions, estimates, fixes, sight
    lines, MPC paths, G) over the top view (the tracks up to the cursor, without the deck).
    Right: the work UAV's error, beta_n, steps in a zone, S and the MPC solve times."""
    low, high = scene.workspace
    centre = (low + high) / 2
    span = float(np.max(high - low))
    formation = rrb.Spatial3DView(
        name="formation",
        origin="/",
        contents=["+ /**", "- /plots/**"],
        eye_controls=rrb.EyeControls3D(  # from the south-west, below the deck, looking up
            position=[centre[0] - 0.2 * span, low[1] + 0.05 * span, low[2] + 0.08 * span],
            look_target=[centre[0], centre[1], low[2] + 0.35 * (high[2] - low[2])],
            eye_up=[0.0, 0.0, 1.0],
        ),
    )
    top = rrb.Spatial3DView(
        name="top view: tracks so far",
        origin="/",
        contents=TRACKED,
        eye_controls=rrb.EyeControls3D(
            position=[centre[0], centre[1] - 1e-3, high[2] + 0.7 * span],
            look_target=[centre[0], centre[1], 0.0],
            eye_up=[0.0, 1.0, 0.0],
        ),
        time_ranges=rr.VisibleTimeRange(
            f.TIMELINE,
            start=rr.TimeRangeBoundary.infinite(),
            end=rr.TimeRangeBoundary.cursor_relative(),
        ),
    )
    hidden = rrb.PlotLegend(visible=False)  # the supports' colours say who is who
    plots = rrb.Vertical(
        rrb.TimeSeriesView(
            name="work UAV error (m)", origin="/plots/work_error", plot_legend=hidden
        ),
        rrb.TimeSeriesView(name="steps in a zone", origin="/plots/zone_steps"),
        rrb.TimeSeriesView(name="beta_n", origin="/plots/beta", plot_legend=hidden),
        rrb.TimeSeriesView(name="fused (in S)", origin="/plots/fused", plot_legend=hidden),
        rrb.TimeSeriesView(name="MPC solve (ms)", origin="/plots/solve_ms", plot_legend=hidden),
        rrb.TimeSeriesView(name="closest approach, least clearance (m)", origin="/plots/margins"),
        *_roles_plot(scene),
    )
    return rrb.Blueprint(
        rrb.Horizontal(
            rrb.Vertical(formation, top, row_shares=[3, 2]), plots, column_shares=[3, 2]
        ),
        rrb.TimePanel(timeline=f.TIMELINE, play_state="following", state="collapsed"),
        collapse_panels=True,
    )


def _roles_plot(scene: Scene) -> list:
    """Where supports have inspections of their own: their roles over time."""
    if not scene.inspections:
        return []
    name = "role (0 formation, 1 inspecting, 2 returning)"
    return [rrb.TimeSeriesView(name=name, origin="/plots/role")]

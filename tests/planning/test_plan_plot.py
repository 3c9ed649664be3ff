"""The plan's figure does not draw a path over a slice of sigma_0 it is not in: each side view
is the slice most of its vehicles' waypoints lie in, and says which; a waypoint off the slice
shown is hollow and named so in the legend."""

from __future__ import annotations

import numpy as np
import pytest

from mission.link.plan_files import Plan, read_vehicle_waypoints
from mission.planning import plan_plot
from mission.planning.plan_plot import OFF_SLICE_M, plot_plan, side_view_groups


@pytest.fixture(scope="module")
def along_plan(along) -> Plan:
    """The shipped plan of the Along scenario."""
    supports = [read_vehicle_waypoints(along, f"support-{n}") for n in (1, 2, 3)]
    return Plan(read_vehicle_waypoints(along, "work"), np.stack(supports))


def test_each_vehicle_is_drawn_over_the_slice_most_of_its_waypoints_lie_in(along_world, along_plan):
    groups = side_view_groups(along_world, along_plan)
    grid = along_world.sigma0_map().grid
    paths = [along_plan.work, *along_plan.supports]
    assert sorted(v for _, vehicles in groups for v in vehicles) == [0, 1, 2, 3]
    for y, vehicles in groups:
        (shown,) = grid.index_of(np.array([[0.0, y, 0.0]]))[:, 1]
        for vehicle in vehicles:
            slices = list(grid.index_of(paths[vehicle])[:, 1])
            assert slices.count(shown) == max(map(slices.count, slices)), (vehicle, y)
            if vehicle:  # a support beside the deck (|y| <= 5 m) is not shown under it
                assert abs(y) > 5.0


def test_the_side_views_say_their_slice_and_hollow_the_waypoints_off_it(
    along_world, along_plan, monkeypatch, tmp_path
):
    drawn = []
    monkeypatch.setattr(plan_plot, "save_figure", lambda fig, path: drawn.append(fig))
    plot_plan(along_world, along_plan, tmp_path / "plan.png")
    (fig,) = drawn
    titles = [ax.get_title() for ax in fig.axes if ax.get_title()]
    groups = side_view_groups(along_world, along_plan)
    assert len(titles) == 1 + len(groups)
    for title, (y, _) in zip(titles[1:], groups, strict=True):
        assert title.startswith("side view of ") and f"sigma_0 at y = {y:g} m" in title
    work_view = next(ax for ax in fig.axes if ax.get_title().startswith("side view of work UAV"))
    labels = work_view.get_legend_handles_labels()[1]
    assert f"hollow: a waypoint > {OFF_SLICE_M:g} m off this slice" in labels
    assert not any(
        "tab:" in label for ax in fig.axes for label in ax.get_legend_handles_labels()[1]
    )

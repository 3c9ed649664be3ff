"""``mission world --plot`` slices its top views where the structure and the task make them
worth seeing (under the deck, at the work UAV's heights, above the structure), not at fixed
heights, and says each height and why in the panel's title."""

from __future__ import annotations

import pytest

from mission.analysis import world_plot
from mission.analysis.slice_heights import deck_underside, slice_heights
from mission.world.model import World

LOW_DECK = """
extends: along
name: low-deck
world:
  structure:
    primitives:
      - {name: deck, min_m: [-20.0, -5.0, 3.0], max_m: [20.0, 5.0, 4.0]}
      - {name: pier, min_m: [-17.0, -3.0, 0.0], max_m: [-15.0, 3.0, 3.0]}
  zones: []
task:
  work_waypoints_m: [[-6.0, -3.0, 2.0], [-3.0, -3.0, 2.0], [0.0, -3.0, 2.5]]
"""


def test_along_is_sliced_under_its_deck_at_the_work_height_and_above(along_world):
    heights = slice_heights(along_world)
    assert [h.z_m for h in heights] == [4.0, 7.0, 11.0]
    assert heights[0].why == "under the deck (its underside at 8 m)"
    assert heights[1].why == "the work UAV's height (7 m)"
    assert heights[2].why == "above the structure (its top at 9 m)"


def test_a_low_deck_moves_every_slice_with_it(write_scenario):
    world = World.load(str(write_scenario(LOW_DECK)))
    assert deck_underside(world) == pytest.approx(3.0)
    heights = slice_heights(world)
    assert [h.z_m for h in heights] == [1.5, 2.0, 6.0]  # 2.5 m shares 2.0's voxel layer
    assert "under the deck" in heights[0].why and "above" in heights[-1].why


def test_nothing_overhanging_makes_no_under_the_deck_slice(write_scenario):
    tower = LOW_DECK.replace("min_m: [-20.0, -5.0, 3.0]", "min_m: [-20.0, -5.0, 0.0]")
    world = World.load(str(write_scenario(tower)))
    assert deck_underside(world) is None
    assert not any("under the deck" in h.why for h in slice_heights(world))


def test_the_top_views_titles_say_each_slice_and_why(write_scenario, monkeypatch, tmp_path):
    drawn = []
    monkeypatch.setattr(world_plot, "save_figure", lambda fig, path, dpi: drawn.append(fig))
    world = World.load(str(write_scenario(LOW_DECK)))
    world_plot.plot_world(world, (0.0, -7.0, 7.0), tmp_path / "w.png")
    (fig,) = drawn
    tops = [ax.get_title() for ax in fig.axes if ax.get_title().startswith("top view")]
    assert tops == [
        "top view (x-y) at z = 1 to 2 m: under the deck (its underside at 3 m)",
        "top view (x-y) at z = 2 to 3 m: the work UAV's height (2 m)",
        "top view (x-y) at z = 6 to 7 m: above the structure (its top at 4 m)",
    ]

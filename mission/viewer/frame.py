"""What the view logs, as plain rows per entity (no Rerun here): a :class:`Frame` is what is new
since the last one; :mod:`mission.viewer.send` turns it into Rerun columns.

Entity paths, colours and sizes are named here once, so the replay, the live view, the layout
and the tests agree on them.
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass, field
from typing import Any

import numpy as np

TIMELINE = "sim_time"  # simulated seconds since the run's epoch

Rgb = tuple[int, int, int]
WORK_COLOUR: Rgb = (230, 57, 70)
SUPPORT_COLOURS: tuple[Rgb, ...] = (
    (30, 136, 229),
    (67, 160, 71),
    (255, 179, 0),
    (142, 36, 170),
    (0, 172, 193),
)
BRIDGE_COLOUR: Rgb = (181, 156, 120)
ZONE_COLOUR: Rgb = (255, 64, 129)
WORKSPACE_COLOUR: Rgb = (120, 120, 120)
ESTIMATE_COLOUR: Rgb = (255, 138, 128)  # xhat
EXCLUDED_COLOUR: Rgb = (140, 140, 140)  # yhat_n of a support left out of S
IN_ZONE_FIX_COLOUR: Rgb = ZONE_COLOUR  # a GNSS fix taken inside a multipath zone
UNKNOWN_COLOUR: Rgb = (200, 200, 200)  # a fix whose truth is not in the log
VISIBLE_COLOUR: Rgb = (224, 224, 224)
BLOCKED_COLOUR: Rgb = (255, 112, 67)
BELOW_MARGIN_COLOUR: Rgb = (213, 0, 0)  # two UAVs closer than the separation margin
WORST_COLOUR: Rgb = (20, 20, 20)  # the worst approach so far
WIND_COLOUR: Rgb = (64, 160, 255)  # the free stream's arrow
# a support off the formation; in the formation it wears its own colour
ROLE_COLOURS: dict[str, Rgb] = {"inspecting": (0, 230, 118), "returning": (213, 0, 249)}
ROLE_LEVELS = {"formation": 0, "inspecting": 1, "returning": 2}  # the roles plot's values
G_RANGE_M = (0.0, 1.2)  # G's colour scale (values above show as the top colour)
G_CHANGED_M = 0.01  # a voxel is shown once G differs from its initial value by this much

ESTIMATE_RADIUS_M = 0.3
FIX_RADIUS_M = 0.12
ROLE_RADIUS_M = 0.2
ROLE_BADGE_M = np.array([0.0, 0.0, 0.7])  # the role's badge, above a support's estimate
EXCLUSION_COLOUR: Rgb = (255, 23, 68)  # a support the integrity monitor excluded
EXCLUSION_BADGE_M = np.array([0.0, 0.0, -0.7])  # its badge, below the estimate
EXCLUSION_RADIUS_M = 0.25


def colour_of(name: str) -> Rgb:
    """A vehicle's colour: the work UAV red, the supports blue, green, amber, ..."""
    if name == "work":
        return WORK_COLOUR
    number = int(name.rsplit("-", 1)[-1])
    return SUPPORT_COLOURS[(number - 1) % len(SUPPORT_COLOURS)]


def uav_path(name: str) -> str:
    """A vehicle's true position (SIM_STATE)."""
    return f"uav/{name}"


def axes_path(name: str) -> str:
    """A flying vehicle's body axes: from the nose's tip through its centre up its thrust axis."""
    return f"uav/{name}/axes"


def estimate_path(name: str) -> str:
    """The ground station's estimate: xhat for the work UAV, yhat_n for a support."""
    return f"estimate/{name}"


def fix_path(name: str) -> str:
    return f"gnss/{name}"


def sight_path(name: str) -> str:
    return f"sight/{name}"


def mpc_path(name: str) -> str:
    return f"mpc/{name}"


def role_path(name: str) -> str:
    """A support's role: a badge above its estimate in the role's colour."""
    return f"role/{name}"


def role_colour(name: str, role: str) -> Rgb:
    """The colour of a support's role: its own in the formation."""
    return ROLE_COLOURS.get(role, colour_of(name))


def exclusion_path(name: str) -> str:
    """A support the integrity monitor excluded: a badge below its estimate (none otherwise)."""
    return f"integrity/{name}/excluded"


def protection_path(name: str) -> str:
    """An estimate's protection radius: a wire sphere around it."""
    return f"integrity/{name}/protection"


def current_waypoint_path(name: str) -> str:
    return f"plan/{name}/current"


def scalar_path(kind: str, name: str | None = None) -> str:
    """``plots/work_error``, ``plots/beta/support-1``, ``plots/solve_ms/...``,
    ``plots/zone_steps/...``, ``plots/fused/...``, ``plots/margins/closest_approach``."""
    return f"plots/{kind}" if name is None else f"plots/{kind}/{name}"


def below_margin_path(first: str, second: str) -> str:
    """The line between two UAVs closer than the separation margin."""
    return f"safety/below_separation/{first}-{second}"


G_PATH = "map/G"
GNSS_ERROR_PATH = "map/gnss_error"  # the true error field beside G (multipath from geometry)
GNSS_ERROR_RANGE_M = (0.0, 20.0)  # its colour scale; a voxel without a fix shows the top
WORST_PATH = "safety/worst_approach"  # between the two UAVs of the worst approach so far


@dataclass
class Rows:
    """One entity's rows: a time and a value each (and a colour, for points and strips)."""

    times: list[float] = field(default_factory=list)
    values: list[Any] = field(default_factory=list)
    colours: list[Rgb] = field(default_factory=list)
    radii: list[float] = field(default_factory=list)  # per row, where an entity's vary

    def add(
        self, time_s: float, value: Any, colour: Rgb | None = None, radius: float | None = None
    ) -> None:
        self.times.append(time_s)
        self.values.append(value)
        if colour is not None:
            self.colours.append(colour)
        if radius is not None:
            self.radii.append(radius)


@dataclass(frozen=True)
class VoxelRow:
    """G where it differs from its initial value, at a snapshot's time."""

    time_s: float
    indices: np.ndarray  # (V, 3) voxel indices
    values: np.ndarray  # (V,) G there, metres


@dataclass
class Frame:
    """New rows since the last frame: points (one position each), strips (one polyline each),
    spheres (a centre and a radius each, drawn as wire), scalars, and G's snapshots."""

    points: dict[str, Rows] = field(default_factory=lambda: defaultdict(Rows))
    strips: dict[str, Rows] = field(default_factory=lambda: defaultdict(Rows))
    spheres: dict[str, Rows] = field(default_factory=lambda: defaultdict(Rows))
    scalars: dict[str, Rows] = field(default_factory=lambda: defaultdict(Rows))
    voxels: list[VoxelRow] = field(default_factory=list)

    def __bool__(self) -> bool:
        return bool(self.points or self.strips or self.spheres or self.scalars or self.voxels)

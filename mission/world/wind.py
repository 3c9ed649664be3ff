"""The wind a flying vehicle feels around the bridge: a mean wind growing with height, shaped by
the structure, plus the run's one field of Dryden turbulence (:mod:`mission.world.turbulence`),
raised in a deck's wake.

**The mean wind** follows the log law, ``U(z) = W20 ln(z / z0) / ln(h20 / z0)``, W20 the
scenario's speed at h20 = 20 ft (6.1 m), z0 ``roughness_length_m`` (EN 1991-1-4's table 4.1:
0.003 m sea, 0.01 m lakes and flat land, 0.05 m grass, 0.3 m villages), held at its value at
10 ft (3.05 m, MIL-F-8785C's lowest height; EN 1991-1-4 holds it below z_min, 1-5 m for those
categories). The direction is the free stream's everywhere.

**The structure** is crude and says so: no flow is solved. A box that does not touch the
ground is a deck, one that does is a pier; a structure from a mesh file shapes nothing. Under
a deck (inside its footprint, below its underside) the mean speed is sheltered:
``shelter + (1 - shelter) exp(-d / edge_width_m)`` of the free stream's, d the horizontal
distance in from the footprint's nearest edge. Around a deck's edges (outside the footprint,
within ``edge_width_m`` of it horizontally and of its height band vertically, not in its lee)
and around the piers (within ``edge_width_m`` of one horizontally, below the deck) the flow
speeds up past the bluff body: mean and gusts ``edge_gain`` times the free stream's.

**The wake** raises the turbulence: PRIME's building-wake model (Schulman, Strimaitis and
Scire 2000, J. Air & Waste Manage. Assoc. 50:378-390; EPA AERMOD's ``prime.f``: the wake's
sigma_v and sigma_w 1.7 times the ambient ones at the lee face, Weil 1996, its speed deficit
0.7, both fading as ``((x + R) / R)^(-2/3)`` with the distance x behind the lee face, rising
linearly over the roof from the upwind face, its wake turbulence used to at most 15 R from the
upwind face). Here: a point in a deck's shadow along the mean wind, at or below its top, is in
its wake; under the deck the gusts' gain rises from 1 at the upwind edge to
``wake_gust_gain`` at the lee edge (in proportion to the way across), behind it
``1 + (wake_gust_gain - 1) ((x + R) / R)^(-2/3)`` up to 15 R behind the lee edge,
R = ``min(H, W)^(2/3) max(H, W)^(1/3)``, H the deck's thickness and W its width across the
wind (each at most 8 times the other, Wilson's limits as PRIME applies them); the gain is
applied to all three components (PRIME gives it for sigma_v and sigma_w). The mean speed
behind the deck is the free stream's (PRIME's deficit is not modelled there); under it the
shelter above. So the turbulence intensity (gust sigma over the mean speed) rises under and
behind a deck: for the default deck in a west wind, 1.7 times the free stream's just behind
the lee edge, 1.35 / 0.36 = 3.8 times mid-way under it.
"""

from __future__ import annotations

import math

import numpy as np

from mission.config.settings import BoxPrimitive
from mission.config.wind_settings import WindSettings
from mission.world.turbulence import FEET, REFERENCE_HEIGHT_M, DrydenScales, FrozenTurbulence

PROFILE_FLOOR_M = 10 * FEET  # the mean wind is held below this height
WAKE_DECAY = 2.0 / 3.0  # PRIME: turbulence and deficit fade as ((x + R) / R)^(-2/3)
WAKE_REACH_R = 15.0  # PRIME's xbyrmax: the wake's turbulence used out to 15 R
WILSON_ASPECT = 8.0  # R's height and width each at most 8 times the other


def blowing_toward(from_deg: float) -> np.ndarray:
    """The unit vector (ENU) a wind from ``from_deg`` (clockwise from north) blows along."""
    bearing = math.radians(from_deg)
    return -np.array([math.sin(bearing), math.cos(bearing), 0.0])


def _horizontal_gap(box: BoxPrimitive, x: float, y: float) -> float:
    """How far (x, y) lies outside a box's footprint (0 inside it)."""
    (x0, y0, _), (x1, y1, _) = box.min_m, box.max_m
    return math.hypot(max(x0 - x, 0, x - x1), max(y0 - y, 0, y - y1))


def _upwind_span(box: BoxPrimitive, x: float, y: float, along: np.ndarray) -> tuple[float, float]:
    """How far upwind of (x, y), on its line along the wind, the box's footprint begins and
    ends: its lee edge, then its windward edge (negative: downwind); (inf, -inf) if the line
    misses it."""
    low, high = -math.inf, math.inf
    for point, start, end, direction in zip((x, y), box.min_m, box.max_m, along):
        if abs(direction) < 1e-12:
            if not start <= point <= end:
                return math.inf, -math.inf
            continue
        a, b = (point - start) / direction, (point - end) / direction
        low, high = max(low, min(a, b)), min(high, max(a, b))
    return (low, high) if low <= high else (math.inf, -math.inf)


def wake_scale(deck: BoxPrimitive, along: np.ndarray) -> float:
    """PRIME's wake length R of a deck in a wind blowing along ``along``: its thickness and
    its width across the wind, each at most 8 times the other."""
    (x0, y0, z0), (x1, y1, z1) = deck.min_m, deck.max_m
    height = z1 - z0
    width = (x1 - x0) * abs(along[1]) + (y1 - y0) * abs(along[0])
    height, width = min(height, WILSON_ASPECT * width), min(width, WILSON_ASPECT * height)
    return min(height, width) ** (2 / 3) * max(height, width) ** (1 / 3)


class WindField:
    """The mean wind at a point (ENU, m/s) and what the structure does to it and its gusts."""

    def __init__(self, settings: WindSettings, boxes: list[BoxPrimitive]) -> None:
        self.settings = settings
        self.boxes = boxes  # what the field was made from, to make it again
        self.along = blowing_toward(settings.from_deg)
        self.free_stream = settings.speed_m_s * self.along  # at 6 m (W20's height)
        self.decks = [b for b in boxes if b.min_m[2] > 0]
        self.piers = [b for b in boxes if b.min_m[2] <= 0]
        self.wake_scales = [wake_scale(deck, self.along) for deck in self.decks]

    def speed_at(self, height_m: float) -> float:
        """The free stream's mean speed at ``height_m`` (the log law)."""
        z0 = self.settings.roughness_length_m
        held = max(height_m, PROFILE_FLOOR_M)
        return self.settings.speed_m_s * math.log(held / z0) / math.log(REFERENCE_HEIGHT_M / z0)

    def mean(self, point: np.ndarray) -> np.ndarray:
        """The mean wind at ``point`` (ENU, m/s)."""
        return self.factor(point) * self.speed_at(float(point[2])) * self.along

    def factor(self, point: np.ndarray) -> float:
        """The local mean speed over the free stream's at ``point``'s height."""
        return self.shaping(point)[0]

    def gust_gain(self, point: np.ndarray) -> float:
        """The local gusts' sigma over the free stream's at ``point``."""
        return self.shaping(point)[1]

    def shaping(self, point: np.ndarray) -> tuple[float, float]:
        """What the structure does at ``point``: (the mean speed's factor, the gusts')."""
        s = self.settings
        x, y, z = (float(v) for v in point)
        for deck, scale in zip(self.decks, self.wake_scales):
            (x0, y0, z0), (x1, y1, z1) = deck.min_m, deck.max_m
            wake = self._wake(deck, scale, x, y, z)
            gain = 1 + (s.wake_gust_gain - 1) * wake
            inside = x0 <= x <= x1 and y0 <= y <= y1
            if inside and z < z0:
                depth = min(x - x0, x1 - x, y - y0, y1 - y)
                return s.shelter + (1 - s.shelter) * math.exp(-depth / s.edge_width_m), gain
            if wake > 0:
                return 1.0, gain
            if (
                not inside
                and _horizontal_gap(deck, x, y) <= s.edge_width_m
                and z0 - s.edge_width_m <= z <= z1 + s.edge_width_m
            ):
                return s.edge_gain, s.edge_gain
        for pier in self.piers:
            if _horizontal_gap(pier, x, y) <= s.edge_width_m and z <= pier.max_m[2]:
                return s.edge_gain, s.edge_gain
        return 1.0, 1.0

    def _wake(self, deck: BoxPrimitive, scale: float, x: float, y: float, z: float) -> float:
        """How strong the deck's wake is at (x, y, z), 0 to 1: across the footprint from the
        upwind edge, then fading behind the lee edge (module docstring)."""
        if z > deck.max_m[2]:
            return 0.0
        lee, windward = _upwind_span(deck, x, y, self.along)
        if windward < 0 or lee > WAKE_REACH_R * scale:
            return 0.0  # upwind of the deck, beside its shadow, or past its wake's reach
        if lee > 0:  # behind the deck
            return ((lee + scale) / scale) ** -WAKE_DECAY
        chord = windward - lee
        return windward / chord if chord > 0 else 1.0


class VehicleWind:
    """The wind one vehicle flies through: the mean wind at its position, shaped by the
    structure, plus the run's gusts there, one vector per substep; it keeps the field's clock
    (the vehicle sets it to the simulated time before each step)."""

    def __init__(
        self, field: WindField, gusts: FrozenTurbulence | None, seed: int, dt_s: float
    ) -> None:
        self.field = field
        self.gusts = gusts  # None: no turbulence (still air, or none asked for)
        self.seed = seed
        self.dt_s = dt_s
        self.time_s = 0.0  # the simulated time of the next substep

    @classmethod
    def of(
        cls, settings: WindSettings, boxes: list[BoxPrimitive], dt_s: float, seed: int
    ) -> VehicleWind:
        """A vehicle's wind in the run of ``seed``, sampled every ``dt_s``."""
        scales = DrydenScales.of(settings.speed_m_s, settings.turbulence)
        gusts = None
        if scales.sigma_w > 0:
            carried = settings.speed_m_s * blowing_toward(settings.from_deg)
            gusts = FrozenTurbulence.of(seed, scales, carried)
        return cls(WindField(settings, boxes), gusts, seed, dt_s)

    def blowing(self, settings: WindSettings) -> VehicleWind:
        """The same run's wind (its field from the same seed) with other settings, at the
        same time: the field is where the new mean wind would have carried it by now."""
        changed = VehicleWind.of(settings, self.field.boxes, self.dt_s, self.seed)
        changed.time_s = self.time_s
        return changed

    def mean_at(self, position: np.ndarray) -> np.ndarray:
        """The mean wind at ``position`` (ENU, m/s), no gusts."""
        return self.field.mean(np.asarray(position, dtype=float).reshape(3))

    def over_step(self, position: np.ndarray, count: int) -> np.ndarray:
        """(count, 3): the wind at ``position`` over the next ``count`` substeps (still air:
        zeros)."""
        start_s, self.time_s = self.time_s, self.time_s + count * self.dt_s
        if self.field.settings.speed_m_s == 0:
            return np.zeros((count, 3))
        point = np.asarray(position, dtype=float).reshape(3)
        factor, gain = self.field.shaping(point)
        mean = factor * self.field.speed_at(float(point[2])) * self.field.along
        if self.gusts is None:
            return np.tile(mean, (count, 1))
        return mean + gain * self.gusts.over_step(point, start_s, self.dt_s, count)

"""The wind a flying vehicle feels around the bridge: a mean wind, shaped by the
structure, with Dryden turbulence.

**The field** (:class:`WindField`) is crude and says so: no flow is solved. A box of the
structure that does not touch the ground is a deck, one that does is a pier. Under a deck
(inside its footprint, below its underside) the wind is sheltered, a wake: the local speed is
``shelter + (1 - shelter) exp(-d / edge_width_m)`` of the free stream, d the horizontal
distance in from the footprint's nearest edge. Around a deck's edges (outside the footprint,
within ``edge_width_m`` of it horizontally and of its height band vertically) and around the
piers (within ``edge_width_m`` of one horizontally, below the deck) the flow speeds up past
the bluff body: ``edge_gain`` times the free stream. Elsewhere the free stream. The direction
is the free stream's everywhere. A structure from a mesh file shapes nothing (no boxes).

**The turbulence** (:class:`DrydenGusts`) is MIL-F-8785C's low-altitude Dryden model (as
RotorPy's ``DrydenGust`` and MATLAB's Dryden block use it), per axis along the mean wind,
across it and vertically: intensity ``sigma_w = turbulence x 0.1 x W20`` with
``sigma_u = sigma_v = sigma_w / (0.177 + 0.000823 h)^0.4`` and scale lengths
``L_u = L_v = h / (0.177 + 0.000823 h)^1.2``, ``L_w = h`` (h in feet, at least 10 ft),
``W20`` the mean speed at 20 ft (the scenario's speed), the frozen turbulence carried past at
the mean speed (at least 0.5 m/s). Shaping filters
``H_u = sigma_u sqrt(2 L_u / (pi V)) / (1 + (L_u / V) s)`` and
``H_v,w = sigma sqrt(L / (pi V)) (1 + sqrt(3) (L / V) s) / (1 + (L / V) s)^2``, discretised
(zero-order hold) at the integration rate and driven by seeded white noise, a block of samples
by a few matrix products (the same numbers as scipy's ``lfilter`` to rounding); each vehicle has
its own draw, so gusts are not correlated between vehicles. The gust scales with the local
speed (the shelter calms it, the edges strengthen it).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from mission.config.settings import BoxPrimitive
from mission.config.wind_settings import WindSettings

FEET = 0.3048
MIN_HEIGHT_FT = 10.0
MIN_SPEED_M_S = 0.5
BLOCK = 256  # gust samples filtered at once


def blowing_toward(from_deg: float) -> np.ndarray:
    """The unit vector (ENU) a wind from ``from_deg`` (clockwise from north) blows along."""
    bearing = math.radians(from_deg)
    return -np.array([math.sin(bearing), math.cos(bearing), 0.0])


def _horizontal_gap(box: BoxPrimitive, x: float, y: float) -> float:
    """How far (x, y) lies outside a box's footprint (0 inside it)."""
    (x0, y0, _), (x1, y1, _) = box.min_m, box.max_m
    return math.hypot(max(x0 - x, 0, x - x1), max(y0 - y, 0, y - y1))


class WindField:
    """The mean wind at a point (ENU, m/s) and the factor the structure puts on it."""

    def __init__(self, settings: WindSettings, boxes: list[BoxPrimitive]) -> None:
        self.settings = settings
        self.free_stream = settings.speed_m_s * blowing_toward(settings.from_deg)
        self.decks = [b for b in boxes if b.min_m[2] > 0]
        self.piers = [b for b in boxes if b.min_m[2] <= 0]

    def factor(self, point: np.ndarray) -> float:
        """The local speed over the free stream's at ``point``."""
        s = self.settings
        x, y, z = (float(v) for v in point)
        for deck in self.decks:
            (x0, y0, z0), (x1, y1, z1) = deck.min_m, deck.max_m
            inside = x0 <= x <= x1 and y0 <= y <= y1
            if inside and z < z0:
                depth = min(x - x0, x1 - x, y - y0, y1 - y)
                return s.shelter + (1 - s.shelter) * math.exp(-depth / s.edge_width_m)
            if (
                not inside
                and _horizontal_gap(deck, x, y) <= s.edge_width_m
                and z0 - s.edge_width_m <= z <= z1 + s.edge_width_m
            ):
                return s.edge_gain
        for pier in self.piers:
            if _horizontal_gap(pier, x, y) <= s.edge_width_m and z <= pier.max_m[2]:
                return s.edge_gain
        return 1.0


def _expm(matrix: np.ndarray) -> np.ndarray:
    """exp(matrix) by scaling and squaring a Taylor series (small, well-scaled matrices: the
    shaping filters' over one substep; numpy only, so a vehicle does not import scipy)."""
    norm = float(np.abs(matrix).sum(axis=1).max())
    squarings = max(0, math.ceil(math.log2(norm)) + 1) if norm > 0 else 0
    scaled = matrix / 2.0**squarings
    term = result = np.eye(len(matrix))
    for k in range(1, 20):
        term = term @ scaled / k
        result = result + term
    for _ in range(squarings):
        result = result @ result
    return result


@dataclass(frozen=True, eq=False)  # hashed by identity: its blocks are cached per filter
class ShapingFilter:
    """One axis's shaping filter, discretised (zero-order hold): x' = A x + B u, y = C x,
    u unit white noise samples, y gust samples (m/s)."""

    a: np.ndarray  # (n, n)
    b: np.ndarray  # (n,)
    c: np.ndarray  # (n,)

    @classmethod
    def of(cls, a: np.ndarray, b: np.ndarray, c: np.ndarray, dt_s: float) -> ShapingFilter:
        """The continuous filter (a, b, c) held over samples ``dt_s`` apart."""
        n = len(a)
        augmented = np.zeros((n + 1, n + 1))
        augmented[:n, :n], augmented[:n, n] = a, b
        held = _expm(augmented * dt_s)
        return cls(held[:n, :n], held[:n, n], np.asarray(c, dtype=float))

    @functools.cache  # noqa: B019 - a handful of filters per process, each kept for its run
    def block(self, count: int) -> tuple[np.ndarray, ...]:
        """For ``count`` samples at once: the outputs' response to the state (count, n) and to
        the inputs (count, count: lower triangular), the state's to the state (n, n) and to
        the inputs (n, count)."""
        powers = [np.eye(len(self.a))]
        for _ in range(count):
            powers.append(powers[-1] @ self.a)
        free = np.array([self.c @ power for power in powers[:count]])
        markov = np.array([0.0] + [self.c @ power @ self.b for power in powers[: count - 1]])
        lags = np.subtract.outer(np.arange(count), np.arange(count))
        forced = np.where(lags >= 0, markov[np.clip(lags, 0, None)], 0.0)
        inputs = np.column_stack([powers[count - 1 - j] @ self.b for j in range(count)])
        return free, forced, powers[count], inputs


def dryden_filters(
    speed_m_s: float, height_m: float, turbulence: float, dt_s: float
) -> list[ShapingFilter]:
    """The three axes' discrete shaping filters: along the mean wind, across it, up; each
    turns unit white noise samples into gust samples (m/s)."""
    v = max(speed_m_s, MIN_SPEED_M_S)
    h_ft = max(height_m / FEET, MIN_HEIGHT_FT)
    sigma_w = turbulence * 0.1 * speed_m_s
    sigma_uv = sigma_w / (0.177 + 0.000823 * h_ft) ** 0.4
    length_uv = h_ft / (0.177 + 0.000823 * h_ft) ** 1.2 * FEET
    length_w = h_ft * FEET
    filters = []
    for axis, (sigma, length) in enumerate(
        [(sigma_uv, length_uv), (sigma_uv, length_uv), (sigma_w, length_w)]
    ):
        tau = length / v
        if axis == 0:  # K / (tau s + 1)
            gain = sigma * math.sqrt(2 * length / (math.pi * v))
            realised = (np.array([[-1 / tau]]), np.array([1.0]), np.array([gain / tau]))
        else:  # K (sqrt(3) tau s + 1) / (tau s + 1)^2, in controllable canonical form
            gain = sigma * math.sqrt(length / (math.pi * v))
            a = np.array([[0.0, 1.0], [-1 / tau**2, -2 / tau]])
            c = np.array([gain / tau**2, gain * math.sqrt(3) / tau])
            realised = (a, np.array([0.0, 1.0]), c)
        filters.append(ShapingFilter.of(*realised, dt_s))
    return filters


class DrydenGusts:
    """One vehicle's turbulence: gust samples (ENU, m/s) at a fixed rate, continuing from one
    call to the next, from its own seeded generator."""

    def __init__(
        self,
        settings: WindSettings,
        height_m: float,
        dt_s: float,
        rng: np.random.Generator,
    ) -> None:
        self.dt_s = dt_s
        self.rng = rng
        self.filters = dryden_filters(settings.speed_m_s, height_m, settings.turbulence, dt_s)
        self.state = [np.zeros(len(f.a)) for f in self.filters]
        along = blowing_toward(settings.from_deg)
        across = np.array([-along[1], along[0], 0.0])
        self.axes = np.column_stack([along, across, [0.0, 0.0, 1.0]])
        # discrete white noise whose spectrum matches the continuous unit one-sided density
        self.noise_scale = math.sqrt(math.pi / dt_s)

    def samples(self, count: int) -> np.ndarray:
        """(count, 3): the next ``count`` gust vectors (filtered a block of at most
        ``BLOCK`` samples at a time: a few matrix products, no loop over samples)."""
        noise = self.rng.standard_normal((3, count)) * self.noise_scale
        gusts = np.empty((3, count))
        for start in range(0, count, BLOCK):
            stop = min(start + BLOCK, count)
            for axis, shaping in enumerate(self.filters):
                free, forced, carry, inputs = shaping.block(stop - start)
                u, x = noise[axis, start:stop], self.state[axis]
                gusts[axis, start:stop] = free @ x + forced @ u
                self.state[axis] = carry @ x + inputs @ u
        return (self.axes @ gusts).T


class VehicleWind:
    """The wind one vehicle flies through: the field's local factor at its position times the
    free stream plus its gusts, one vector per substep."""

    def __init__(
        self, field: WindField, gusts: DrydenGusts, boxes: list[BoxPrimitive], height_m: float
    ) -> None:
        self.field = field
        self.gusts = gusts
        self.boxes = boxes  # what the field was made from, to make it again
        self.height_m = height_m

    @classmethod
    def of(
        cls,
        settings: WindSettings,
        boxes: list[BoxPrimitive],
        height_m: float,
        dt_s: float,
        rng: np.random.Generator,
    ) -> VehicleWind:
        """A vehicle's wind, its gusts' scale lengths set by its height."""
        gusts = DrydenGusts(settings, height_m, dt_s, rng)
        return cls(WindField(settings, boxes), gusts, boxes, height_m)

    def mean_at(self, position: np.ndarray) -> np.ndarray:
        """The mean wind at ``position`` (ENU, m/s): no gusts, no draw."""
        return self.field.factor(position) * self.field.free_stream

    def over_step(self, position: np.ndarray, count: int) -> np.ndarray:
        """(count, 3): the wind at ``position`` over the next ``count`` substeps (still air:
        zeros, and no draw)."""
        if self.field.settings.speed_m_s == 0:
            return np.zeros((count, 3))
        factor = self.field.factor(position)
        return factor * (self.field.free_stream + self.gusts.samples(count))

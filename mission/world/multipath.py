"""A GNSS receiver near a structure: which signals it tracks, the pseudorange error
each carries, and the position it solves from them.

Per satellite above the mask, from the paths of :mod:`mission.world.reflections`:

- **direct received**: tracked at the open-sky C/N0; its echoes (every received reflection)
  pull the code tracking by the early-minus-late envelope (:mod:`mission.world.code_tracking`);
- **direct blocked, a reflection received** (NLOS): tracked on the strongest reflection, whose
  whole excess path is the error, at that reflection's C/N0;
- below ``cn0_floor_dbhz``, or nothing received: lost.

With ``solution: rtk`` (the default; sigma_UERE = 0.1 m is an RTK receiver's) the carrier
solution is fixed while every tracked signal is direct: the echoes' code errors do not reach
it (carrier multipath, at most a quarter wavelength, 5 cm, is left to sigma_UERE). A tracked
reflection keeps the ambiguities from being fixed (its carrier is as late as its code): the
receiver reports a float solution that carries the code errors, echoes included. With
``solution: code`` the code errors always count.

The fix is the weighted least-squares solution of the biased pseudoranges, as a receiver
computes it: unknowns are the position and one clock per constellation in use, weights
1/sigma^2 with sigma^2 proportional to 1/(C/N0) (so equal weights in the open sky, where the
fix's geometry is exactly today's), and the position error is the first three components of
(H^T W H)^-1 H^T W b for the pseudorange errors b. The satellites are far enough for H not to
depend on the receiver's position, so this linear solution is the iterated one's.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mission.config.signal_settings import SignalSettings
from mission.world.code_tracking import chip_length_m, echo_error_chips
from mission.world.gnss import (
    GnssFix,
    GnssModel,
    cholesky_or_none,
    least_squares_fix,
    noisy_fix,
)
from mission.world.reflections import ReflectedPaths, Reflectors

_UNFIXED_SOLUTION = {"rtk": "rtk-float", "code": "code"}  # a fix not carrier-fixed


@dataclass(frozen=True)
class ReceiverSolution:
    """What a receiver at N points makes of the sky (S satellites, those below the mask
    never tracked)."""

    tracked: np.ndarray  # (N, S) the satellite is used in the fix
    reflected: np.ndarray  # (N, S) tracked on a reflection (NLOS)
    range_error_m: np.ndarray  # (N, S) pseudorange error (0 where not tracked)
    cn0_dbhz: np.ndarray  # (N, S) of the tracked signal (NaN where not tracked)
    has_fix: np.ndarray  # (N,)
    carrier_fixed: np.ndarray  # (N,) an RTK fix: no code error reaches the position
    position_error_m: np.ndarray  # (N, 3) the fix's error without noise (NaN without fix)
    cov_geom: np.ndarray  # (N, 3, 3) (H^T W H)^-1's position block (NaN without fix)

    @property
    def n_used(self) -> np.ndarray:
        """Satellites in each fix."""
        return self.tracked.sum(axis=1)


class GeometricReceiver:
    """Receivers' fixes from the structure's geometry: deterministic for a position."""

    def __init__(self, gnss: GnssModel, signal: SignalSettings, source: str = "") -> None:
        self.gnss = gnss
        self.signal = signal
        sky = gnss.sky
        self._above = np.flatnonzero(sky.above_mask)
        self._directions = sky.directions_enu[self._above]
        self._chip_m = chip_length_m(sky.system)
        self._system = sky.constellation_index()
        self.reflectors = Reflectors(
            gnss.structure,
            self._directions,
            signal.amplitude.of(signal.structure_surface),
            signal.amplitude.of(signal.ground_surface),
            signal.antenna_below_horizon_db,
            source,
        )

    def paths(self, points: np.ndarray) -> ReflectedPaths:
        """The received reflections at ``points``, satellites indexed as in the sky."""
        found = self.reflectors.paths(points)
        return ReflectedPaths(
            found.point,
            self._above[found.satellite],
            found.plane,
            found.excess_m,
            found.amplitude,
            found.specular_m,
        )

    def solve(self, points: np.ndarray) -> ReceiverSolution:
        """Tracked signals, their errors and the fix at each of ``points`` (N, 3)."""
        points = np.atleast_2d(np.asarray(points, dtype=float))
        n_points, n_sats = len(points), len(self._chip_m)
        direct = self.gnss.visibility(points)
        paths = self.paths(points)
        chips = self._chip_m[paths.satellite]
        echo = direct[paths.point, paths.satellite]
        error = np.zeros((n_points, n_sats))
        np.add.at(
            error,
            (paths.point[echo], paths.satellite[echo]),
            chips[echo]
            * echo_error_chips(
                paths.amplitude[echo],
                paths.excess_m[echo] / chips[echo],
                self.signal.correlator_spacing_chips,
            ),
        )
        cn0 = np.where(direct, self.signal.cn0_open_sky_dbhz, np.nan)
        reflected, error, cn0 = self._strongest_reflections(paths, ~direct, error, cn0)
        tracked = np.isfinite(cn0) & (cn0 >= self.signal.cn0_floor_dbhz)
        reflected &= tracked
        error = np.where(tracked, error, 0.0)
        carrier_fixed = np.zeros(n_points, dtype=bool)
        if self.signal.solution == "rtk":
            carrier_fixed = ~reflected.any(axis=1)
        weight = np.where(tracked, 10 ** ((cn0 - self.signal.cn0_open_sky_dbhz) / 10), 0.0)
        has_fix, position_error, cov = least_squares_fix(
            self.gnss.geometry_rows,
            self._system,
            weight,
            np.where(carrier_fixed[:, None], 0.0, error),
        )
        carrier_fixed &= has_fix
        return ReceiverSolution(
            tracked, reflected, error, cn0, has_fix, carrier_fixed, position_error, cov
        )

    def _strongest_reflections(
        self, paths: ReflectedPaths, blocked: np.ndarray, error: np.ndarray, cn0: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Where the direct signal is blocked, track the strongest reflection (the shorter on
        a tie): (where one is tracked, ``error`` with its excess path there, ``cn0`` with its
        C/N0 there)."""
        error, cn0 = error.copy(), cn0.copy()
        nlos = blocked[paths.point, paths.satellite] & (paths.amplitude > 0)
        point, sat = paths.point[nlos], paths.satellite[nlos]
        amplitude, excess = paths.amplitude[nlos], paths.excess_m[nlos]
        order = np.lexsort((excess, -amplitude, sat, point))  # strongest first in each pair
        point, sat, amplitude, excess = point[order], sat[order], amplitude[order], excess[order]
        first = np.ones(len(point), dtype=bool)
        first[1:] = (point[1:] != point[:-1]) | (sat[1:] != sat[:-1])
        point, sat = point[first], sat[first]
        error[point, sat] = excess[first]
        cn0[point, sat] = self.signal.cn0_open_sky_dbhz + 20 * np.log10(amplitude[first])
        reflected = np.zeros_like(blocked)
        reflected[point, sat] = True
        return reflected, error, cn0

    def sample_fix(
        self,
        point: np.ndarray,
        rng: np.random.Generator,
        offset_m: np.ndarray | None = None,
        sigma_uere_m: float | None = None,
        scale: float = 1.0,
    ) -> GnssFix:
        """One fix at true position ``point``: truth + ``scale`` x the geometric error +
        N(0, sigma^2 cov_geom) + ``offset_m`` (a zone's, with ``both``); the same draws as
        :meth:`GnssModel.sample_fix`."""
        point = np.asarray(point, dtype=float).reshape(3)
        solution = self.solve(point[None])
        n_used = int(solution.n_used[0])
        cov_geom = solution.cov_geom[0] if solution.has_fix[0] else None
        factor = cholesky_or_none(cov_geom) if cov_geom is not None else None
        sigma = self.gnss.settings.sigma_uere_m if sigma_uere_m is None else sigma_uere_m
        fixed = bool(solution.carrier_fixed[0]) or scale == 0  # no bias left to float on
        kind = "rtk-fixed" if fixed else _UNFIXED_SOLUTION[self.signal.solution]
        bias = scale * solution.position_error_m[0] if solution.has_fix[0] else 0.0
        return noisy_fix(point + bias, cov_geom, factor, n_used, rng, sigma, offset_m, kind)

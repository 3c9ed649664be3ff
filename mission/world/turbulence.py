"""One frozen field of Dryden turbulence for the whole run, carried past by the mean wind: every
vehicle samples the same field at its own position and time, so vehicles near each other feel
correlated gusts.

**The intensities and scales** are MIL-F-8785C's low-altitude Dryden model's (as RotorPy's
``DrydenGust`` and MATLAB's Dryden block use it) at one height for the whole field,
``REFERENCE_HEIGHT_M`` = 20 ft (6.1 m, where W20, the scenario's speed, is given):
``sigma_w = turbulence x 0.1 x W20``, ``sigma_u = sigma_v = sigma_w / (0.177 + 0.000823 h)^0.4``
(1.93 sigma_w), ``L_u = L_v = h / (0.177 + 0.000823 h)^1.2`` (43.8 m), ``L_w = h`` (6.1 m),
h in feet.

**The field** is a sum of random Fourier modes, ``u(x) = sum_n a_n cos(k_n . x + psi_n)`` with
``a_n`` perpendicular to ``k_n`` (divergence-free), of a homogeneous isotropic field whose
longitudinal correlation is Dryden's ``f(r) = exp(-r / L)``: its energy spectrum is
``E(k) = (8 sigma^2 L / pi) (kL)^4 / (1 + (kL)^2)^3`` (``E = 1/2 k^3 d/dk (1/k dE11/dk)`` of
the one-dimensional ``E11 = (2 sigma^2 L / pi) / (1 + (kL)^2)``), so the transverse
correlation is ``g(r) = exp(-r / L) (1 - r / 2L)`` and the spectra along a line are Dryden's
``H_u``, ``H_v`` and ``H_w``. Two such fields, since L differs by axis: one of scale ``L_u``
and intensity ``sigma_u`` gives the two horizontal components, one of ``L_w`` and ``sigma_w``
the vertical one (their cross-correlation is zero, as in an isotropic field at one point).
Each field has ``SHELLS`` wavenumber shells: in kL one from 0 to ``KL_LOW``, log-spaced ones to
``KL_HIGH``, and the tail (0.85 % of the energy) from there to ``KL_TOP`` (the 0.02 % beyond
is left out and the rest scaled to the whole variance); a shell's energy is E(k)'s integral
over it. In a shell the wavevectors point along the six axes of an icosahedron turned by a
random rotation of the shell's own, two perpendicular polarisations each, each with a random
phase, and each wavenumber is drawn from E(k) within the shell. The six axes make
``sum_d d d^T`` a multiple of the identity, so every component's variance is sigma^2 in every
draw, not on average only; drawing the wavenumbers from E(k) makes the expected correlation at
any separation the spectrum's exactly. The frozen field is carried along the mean wind V:
``gust(x, t) = u(x - V t)`` (Taylor's hypothesis at one speed for every height).

**Cheap over a step**: a vehicle samples the field at one point for ``count`` substeps. With
``phi_n = k_n . x - omega_n t_m + psi_n`` at the step's middle ``t_m`` and ``omega_n = k_n . V``,
the sample ``d`` after the middle is ``sum_n a_n (cos(phi_n) cos(omega_n d) + sin(phi_n)
sin(omega_n d))`` and the one ``d`` before it the same with a minus: the cosines and sines of
``omega_n d`` over half a step are kept (double precision), so a step is ``2N`` trigonometric
values and two matrix products ``(count / 2, N) x (N, 3)`` (0.04 ms for 125 substeps and
N = 840 in one process; the gusts good to ~1e-6 of themselves).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

FEET = 0.3048
REFERENCE_HEIGHT_M = 20 * FEET  # W20's height: the field's intensities and scale lengths
WIND_STREAM = 0x57494E44  # "WIND": the run's seed and this make the field's generator
SHELLS = (30, 40)  # wavenumber shells of the horizontal field (L_u), of the vertical (L_w)
# the shells in kL: [0, KL_LOW], log-spaced ones to KL_HIGH, the tail [KL_HIGH, KL_TOP]
KL_LOW, KL_HIGH, KL_TOP = 0.05, 200.0, 1e4
GOLDEN = (1 + math.sqrt(5)) / 2
# the six axes through an icosahedron's opposite vertices: sum d d^T = 2 I
ICOSAHEDRON_AXES = np.array(
    [
        (0, 1, GOLDEN),
        (0, -1, GOLDEN),
        (1, GOLDEN, 0),
        (-1, GOLDEN, 0),
        (GOLDEN, 0, 1),
        (GOLDEN, 0, -1),
    ]
) / math.sqrt(1 + GOLDEN**2)


@dataclass(frozen=True)
class DrydenScales:
    """MIL-F-8785C's low-altitude intensities (m/s) and scale lengths (m) at one height."""

    sigma_uv: float
    sigma_w: float
    length_uv_m: float
    length_w_m: float

    @classmethod
    def of(
        cls, speed_m_s: float, turbulence: float, height_m: float = REFERENCE_HEIGHT_M
    ) -> DrydenScales:
        """At ``height_m`` (at least 10 ft) for W20 = ``speed_m_s`` and light turbulence
        scaled by ``turbulence`` (1: MIL-F-8785C's)."""
        h_ft = max(height_m / FEET, 10.0)
        sigma_w = turbulence * 0.1 * speed_m_s
        lapse = 0.177 + 0.000823 * h_ft
        return cls(sigma_w / lapse**0.4, sigma_w, h_ft / lapse**1.2 * FEET, h_ft * FEET)


def energy_fraction(kl: np.ndarray) -> np.ndarray:
    """The fraction of E(k)'s energy below wavenumber ``kl`` (in units of 1/L):
    ``int_0^x s^4 / (1 + s^2)^3 ds`` over its whole, 3 pi / 16."""
    x = np.asarray(kl, dtype=float)
    below = 3 * np.arctan(x) / 8 - x * (5 * x**2 + 3) / (8 * (1 + x**2) ** 2)
    return below / (3 * math.pi / 16)


def energy_density(kl: np.ndarray) -> np.ndarray:
    """The derivative of :func:`energy_fraction`: E(k)'s shape, ``x^4 / (1 + x^2)^3`` over
    3 pi / 16."""
    x = np.asarray(kl, dtype=float)
    return x**4 / (1 + x**2) ** 3 / (3 * math.pi / 16)


def wavenumbers_of(fractions: np.ndarray, low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """kL where :func:`energy_fraction` reaches ``fractions``, each between its shell's edges
    ``low`` and ``high``: 24 halvings (to ~1e-7 of the shell), then three Newton steps."""
    low, high = np.array(low, dtype=float), np.array(high, dtype=float)
    for _ in range(24):
        middle = 0.5 * (low + high)
        below = energy_fraction(middle) < fractions
        low, high = np.where(below, middle, low), np.where(below, high, middle)
    kl = 0.5 * (low + high)
    for _ in range(3):
        step = (energy_fraction(kl) - fractions) / np.maximum(energy_density(kl), 1e-300)
        kl = np.clip(kl - step, low, high)
    return kl


def rotations(quaternions: np.ndarray) -> np.ndarray:
    """(n, 3, 3): the rotations of ``quaternions`` (n, 4; w, x, y, z), each normalised (four
    normal draws make a uniformly random rotation)."""
    w, x, y, z = (quaternions / np.linalg.norm(quaternions, axis=1)[:, None]).T
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
        ],
        1,
    )


def isotropic_modes(
    rng: np.random.Generator, length_m: float, shells: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unit-variance modes of the isotropic field of scale ``length_m``: wavevectors (N, 3,
    rad/m), amplitudes (N, 3, m/s for sigma 1) and phases (N,), N = 12 ``shells``."""
    edges = np.concatenate([[0.0], np.geomspace(KL_LOW, KL_HIGH, shells - 1), [KL_TOP]])
    below = energy_fraction(edges)
    energy = 1.5 * np.diff(below) / below[-1]  # of the three components' sum, sigma 1
    axes = len(ICOSAHEDRON_AXES)
    turned = rotations(rng.standard_normal((shells, 4)))  # (shells, 3, 3)
    drawn = below[:-1, None] + np.diff(below)[:, None] * rng.random((shells, axes))
    kl = wavenumbers_of(drawn, edges[:-1, None], edges[1:, None])  # (shells, axes)
    directions = np.einsum("sij,dj->sdi", turned, ICOSAHEDRON_AXES)
    least_along = np.eye(3)[np.argmin(np.abs(directions), axis=-1)]  # never parallel
    first = np.cross(directions, least_along)
    first /= np.linalg.norm(first, axis=-1, keepdims=True)
    second = np.cross(directions, first)
    # each polarisation's mode carries half its amplitude^2 as variance: D q^2 = 2 E per shell
    amplitude = np.sqrt(2 * energy / axes)[:, None, None]
    wavevectors = np.concatenate([directions * kl[..., None] / length_m] * 2, axis=1)
    amplitudes = np.concatenate([first * amplitude, second * amplitude], axis=1)
    phases = rng.uniform(0.0, 2 * math.pi, (shells, 2 * axes))
    return wavevectors.reshape(-1, 3), amplitudes.reshape(-1, 3), phases.reshape(-1)


class FrozenTurbulence:
    """The run's gust field (ENU, m/s): ``sum_n a_n cos(k_n . (x - V t) + psi_n)``, the
    horizontal components from one set of modes, the vertical from another (each mode's
    amplitude is zero in the components its set does not feed)."""

    def __init__(
        self,
        wavevectors: np.ndarray,
        amplitudes: np.ndarray,
        phases: np.ndarray,
        carried: np.ndarray,
    ) -> None:
        self.wavevectors = wavevectors  # (N, 3), rad/m
        self.amplitudes = amplitudes  # (N, 3), m/s
        self.phases = phases  # (N,)
        self.frequencies = wavevectors @ np.asarray(carried, dtype=float)  # omega_n, rad/s
        self._steps: dict = {}  # per (count, dt): a step's cosines and sines

    @classmethod
    def of(cls, seed: int, scales: DrydenScales, carried: np.ndarray) -> FrozenTurbulence:
        """The field of the run's ``seed`` (the same in every process: its draws depend on
        the seed alone), of ``scales``, carried along ``carried`` (m/s)."""
        rng = np.random.default_rng(np.random.SeedSequence([seed, WIND_STREAM]))
        k_h, a_h, psi_h = isotropic_modes(rng, scales.length_uv_m, SHELLS[0])
        k_w, a_w, psi_w = isotropic_modes(rng, scales.length_w_m, SHELLS[1])
        horizontal = a_h * np.array([scales.sigma_uv, scales.sigma_uv, 0.0])
        vertical = a_w * np.array([0.0, 0.0, scales.sigma_w])
        return cls(
            np.vstack([k_h, k_w]),
            np.vstack([horizontal, vertical]),
            np.concatenate([psi_h, psi_w]),
            carried,
        )

    def at(self, points: np.ndarray, time_s: float) -> np.ndarray:
        """(P, 3): the gusts at ``points`` (P, 3) at ``time_s``."""
        points = np.atleast_2d(np.asarray(points, dtype=float))
        phase = points @ self.wavevectors.T - self.frequencies * time_s + self.phases
        return np.cos(phase) @ self.amplitudes

    def over_step(self, point: np.ndarray, start_s: float, dt_s: float, count: int) -> np.ndarray:
        """(count, 3): the gusts at ``point`` at ``start_s + j dt_s``, j < ``count``: from the
        step's middle, ``cos(phi - omega d) = cos(phi) cos(omega d) + sin(phi) sin(omega d)``
        at ``d`` after it and ``cos(phi) cos(omega d) - sin(phi) sin(omega d)`` before it."""
        cosines, sines = self._step_bases(count, dt_s)
        middle_s = start_s + 0.5 * (count - 1) * dt_s
        phase = self.wavevectors @ np.asarray(point, dtype=float) - self.frequencies * middle_s
        phase += self.phases
        even = cosines @ (np.cos(phase)[:, None] * self.amplitudes)
        odd = sines @ (np.sin(phase)[:, None] * self.amplitudes)
        half = len(even)
        gusts = np.empty((count, 3))
        gusts[count - half :] = even + odd
        gusts[:half] = (even - odd)[::-1]
        return gusts

    def _step_bases(self, count: int, dt_s: float) -> tuple[np.ndarray, np.ndarray]:
        """(half the step, N) each: ``cos(omega_n d_m)`` and ``sin(omega_n d_m)`` at the
        offsets ``d_m`` from the step's middle, kept per step (in double precision: single
        precision's products differ with the SIMD kernels BLAS picks, at 1e-7 of the gusts,
        and a run's decisions with them; double's, at 1e-16, do not move them)."""
        key = (count, dt_s)
        if key not in self._steps:
            offsets = (np.arange((count + 1) // 2) + (0.0 if count % 2 else 0.5)) * dt_s
            turned = np.outer(offsets, self.frequencies)
            self._steps[key] = (np.cos(turned), np.sin(turned))
        return self._steps[key]

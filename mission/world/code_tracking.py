"""What a receiver's code tracking makes of a direct signal and its echoes.

The delay lock loop is a coherent early-minus-late discriminator with spacing ``d`` chips on
the ideal triangular autocorrelation R(x) = max(0, 1 - |x|) of a BPSK code (infinite
front-end bandwidth). One echo of relative amplitude ``a`` and delay ``tau`` chips, in phase
with the direct signal, moves the tracking point to where

    D(e) = R(e - d/2) - R(e + d/2) + a [R(e - tau - d/2) - R(e - tau + d/2)] = 0,

which is piecewise linear in ``e`` and solved here in closed form (the upper edge of the
classic multipath error envelope; Braasch, "Multipath", in Springer Handbook of GNSS, 2017):

- tau <= (1 + a) d/2:             e = a tau / (1 + a)
- ... <= 1 - d/2 + a d/2:         e = a d/2                    (the narrow correlator's plateau)
- ... <= 1 + d/2:                 e = a (1 + d/2 - tau) / (2 - a)
- beyond:                         e = 0

Echoes of one satellite add (first order in the amplitudes). The tests check the closed form
against a numerical root of D.
"""

from __future__ import annotations

import numpy as np

SPEED_OF_LIGHT_M_S = 299_792_458.0
# code chip lengths by constellation letter (metres): GPS, Galileo, QZSS and NavIC share
# 1.023 Mchip/s on L1; GLONASS L1OF 0.511; BeiDou B1I 2.046. Galileo's BOC(1,1) is treated
# as the BPSK it is modulated on, a simplification (its envelope is narrower).
CHIP_RATE_HZ = {"G": 1.023e6, "E": 1.023e6, "J": 1.023e6, "I": 1.023e6, "R": 0.511e6, "C": 2.046e6}
DEFAULT_CHIP_RATE_HZ = 1.023e6


def chip_length_m(systems: tuple[str, ...]) -> np.ndarray:
    """The code chip's length in metres of each satellite, by its constellation letter."""
    return np.array(
        [SPEED_OF_LIGHT_M_S / CHIP_RATE_HZ.get(s, DEFAULT_CHIP_RATE_HZ) for s in systems]
    )


def echo_error_chips(amplitude: np.ndarray, delay: np.ndarray, spacing: float) -> np.ndarray:
    """Tracking error (chips, >= 0) that one in-phase echo of ``amplitude`` (< 1, relative to
    the direct signal) and ``delay`` (chips, >= 0) causes with correlator ``spacing``."""
    a = np.asarray(amplitude, dtype=float)
    tau = np.asarray(delay, dtype=float)
    half = spacing / 2
    short = a * tau / (1 + a)
    plateau = a * half
    tail = a * (1 + half - tau) / (2 - a)
    error = np.where(
        tau <= (1 + a) * half,
        short,
        np.where(tau <= 1 - half + plateau, plateau, np.where(tau <= 1 + half, tail, 0.0)),
    )
    return np.maximum(error, 0.0)


def discriminator(error: np.ndarray, amplitude: float, delay: float, spacing: float) -> np.ndarray:
    """D(e) of the module's docstring (for the tests' numerical root)."""

    def r(x: np.ndarray) -> np.ndarray:
        return np.maximum(0.0, 1.0 - np.abs(x))

    half = spacing / 2
    direct = r(error - half) - r(error + half)
    echo = r(error - delay - half) - r(error - delay + half)
    return direct + amplitude * echo

"""The thrust gain of a rotor near a surface, T/T0 as a function of the distance d from the
rotor's plane to the surface (docs/model.md, "Near surfaces"). Written with arithmetic only, so
the same function gives a number for a float and an expression for a casadi symbol; here, not
with the dynamics, so that the settings can refuse a law that is infinite where it is used.

- **Ceiling, measured**: Hsiao and Chirarattananon (2019, "Ceiling effects for hybrid
  aerial-surface locomotion of small rotorcraft", IEEE/ASME Trans. Mechatronics) model the
  ceiling by momentum theory: T/T0 = gamma^2 with
  gamma = (1 - a1 delta^2) / 2 + sqrt((1 - a1 delta^2)^2 + (a0 / 8) delta^2) / 2, delta = R / d,
  and their constants a0 = 1.6, a1 = 0 (as a public implementation of the model carries them;
  we could not read the paper's text). It gives 1.10 at d = R, 1.37 at R/2 and 2.32 at R/4.
- **Ground, measured**: Sanchez-Cuevas, Heredia and Ollero (2017, "Characterization of the
  aerodynamic ground effect and its influence in multirotor control", Int. J. Aerospace Eng.),
  eq. 7, which adds the neighbouring rotors' images and the body's lift to Cheeseman and
  Bennett's: T/T0 = 1 / (1 - (R/4z)^2 - R^2 z / sqrt(d^2 + 4z^2)^3
  - (R^2/2) z / sqrt(2 d^2 + 4z^2)^3 - 2 R^2 z K_b / sqrt(b^2 + 4z^2)^3), d the distance between
  neighbouring rotors, b between opposite ones, K_b = 2 (their fitted body-lift constant, as
  an implementation citing eq. 7 carries it).
- **Image**: Cheeseman and Bennett (1955), T/T0 = 1 / (1 - (R / 4d)^2), above and below.

Every law holds its value at ``proximity_clip_radii`` rotor radii closer in.
"""

from __future__ import annotations

from typing import Any, Protocol


class RotorLayout(Protocol):
    """What the laws read of a multicopter's settings."""

    rotor_radius_m: float
    proximity_clip_radii: float
    ceiling_model: str
    ground_model: str
    lever_m: float

    @property
    def rotor_arm_m(self) -> float: ...


CEILING_A0, CEILING_A1 = 1.6, 0.0  # Hsiao and Chirarattananon (2019)
GROUND_BODY_LIFT = 2.0  # Sanchez-Cuevas et al. (2017)'s K_b


def _held(body: RotorLayout, distance_m: Any, maximum: Any) -> Any:
    """``distance_m`` no closer than the clip (``maximum``: fmax for the type at hand)."""
    return maximum(distance_m, body.proximity_clip_radii * body.rotor_radius_m)


def ceiling_gain(body: RotorLayout, distance_m: Any, maximum: Any = max) -> Any:
    """T/T0 of a rotor ``distance_m`` below a surface, by ``body.ceiling_model``."""
    d = _held(body, distance_m, maximum)
    delta2 = (body.rotor_radius_m / d) ** 2
    if body.ceiling_model == "measured":
        a = 1 - CEILING_A1 * delta2
        gamma = a / 2 + (a**2 + CEILING_A0 / 8 * delta2) ** 0.5 / 2
        return gamma**2
    if body.ceiling_model == "image":
        return 1 / (1 - delta2 / 16)
    return 1.0 + 0 * d


def ground_gain_denominator(body: RotorLayout, height_m: Any) -> Any:
    """The ground law's denominator at ``height_m`` (the gain is its inverse)."""
    r, z = body.rotor_radius_m, height_m
    images = 1 - (r / (4 * z)) ** 2
    if body.ground_model != "measured":
        return images
    near, far = 2 * body.lever_m, 2 * body.rotor_arm_m  # neighbouring and opposite rotors
    images -= r**2 * z / (near**2 + 4 * z**2) ** 1.5
    images -= r**2 / 2 * z / (2 * near**2 + 4 * z**2) ** 1.5
    return images - 2 * r**2 * z * GROUND_BODY_LIFT / (far**2 + 4 * z**2) ** 1.5


def ground_gain(body: RotorLayout, height_m: Any, maximum: Any = max) -> Any:
    """T/T0 of a rotor ``height_m`` above a surface, by ``body.ground_model``."""
    z = _held(body, height_m, maximum)
    if body.ground_model == "none":
        return 1.0 + 0 * z
    return 1 / ground_gain_denominator(body, z)

"""The wind around the bridge: the run's one frozen Dryden field (its sigma and its correlation
between points 3 m apart against MIL-F-8785C's, over many seeds; its spectra at a hovering
point), the mean wind's log law, the structure's shelter, speed-up and wake where the field
says, the same field for the same seed, still air as still, and settings that cannot be."""

from __future__ import annotations

import itertools
import math
from dataclasses import replace

import numpy as np
import pytest

from mission.config.errors import FieldProblem
from mission.config.scenario import load_scenario
from mission.world.turbulence import FEET, DrydenScales, FrozenTurbulence
from mission.world.wind import VehicleWind, WindField

ALONG = load_scenario("along")
WIND = replace(ALONG.world.wind, speed_m_s=6.0, from_deg=270.0)  # a west wind: it blows east
BOXES = list(ALONG.world.structure.primitives)
DT_S = 0.004  # a multicopter's substep (250 Hz)
EAST = np.array([1.0, 0.0, 0.0])


def _dryden_by_hand() -> tuple[float, float, float, float]:
    """MIL-F-8785C's low altitude at the field's height, h = 20 ft, W20 = 6 m/s:
    sigma_w = 0.1 W20, sigma_u = sigma_v = sigma_w / (0.177 + 0.000823 h)^0.4,
    L_u = L_v = h / (0.177 + 0.000823 h)^1.2, L_w = h (h in feet)."""
    h_ft = 20.0
    sigma_w = 0.1 * 6.0  # 0.6 m/s
    sigma_uv = sigma_w / (0.177 + 0.000823 * h_ft) ** 0.4  # 1.157 m/s
    length_uv = h_ft / (0.177 + 0.000823 * h_ft) ** 1.2 * FEET  # 43.77 m
    return sigma_uv, sigma_w, length_uv, h_ft * FEET  # L_w 6.096 m


def _correlation_at(r_m: float, length_m: float, longitudinal: bool) -> float:
    """Dryden's correlation of a component between points ``r_m`` apart: along the
    separation (longitudinal) ``f(r) = exp(-r / L)``, the exponential whose spectrum
    ``2 sigma^2 L / pi / (1 + (L Omega)^2)`` is H_u's; across it (transverse, for an
    isotropic incompressible field) ``g = f + (r / 2) f' = exp(-r / L) (1 - r / 2L)``, whose
    spectrum ``sigma^2 L / pi (1 + 3 (L Omega)^2) / (1 + (L Omega)^2)^2`` is H_v's and H_w's."""
    f = math.exp(-r_m / length_m)
    return f if longitudinal else f * (1 - r_m / (2 * length_m))


SEEDS = 2000  # independent draws of the field, one sample each at three points
START = np.array([0.0, 12.0, 6.0])  # in the open, north of the deck
APART = {"along": np.array([3.0, 0.0, 0.0]), "across": np.array([0.0, 3.0, 0.0])}


@pytest.fixture(scope="module")
def gusts_over_seeds() -> np.ndarray:
    """(SEEDS, 3 points, 3 axes): the gusts a vehicle's wind (mean taken off) gives at START
    and 3 m east (along the wind) and north (across it), at 40 s, one run seed each."""
    points = [START, START + APART["along"], START + APART["across"]]
    samples = np.empty((SEEDS, 3, 3))
    for seed in range(SEEDS):
        wind = VehicleWind.of(WIND, [], DT_S, seed)
        mean = wind.field.mean(START)
        for i, point in enumerate(points):
            wind.time_s = 40.0
            samples[seed, i] = wind.over_step(point, 1)[0] - mean
    return samples


def test_one_point_sigma_is_mil_f_8785cs(gusts_over_seeds):
    sigma_uv, sigma_w, _, _ = _dryden_by_hand()
    # the sample sigma of n normal draws has a standard error sigma / sqrt(2 (n - 1)): 1.6 %
    tolerance = 4 / math.sqrt(2 * (SEEDS - 1))
    found = gusts_over_seeds[:, 0].std(axis=0)
    assert found == pytest.approx([sigma_uv, sigma_uv, sigma_w], rel=tolerance)
    # and in every draw the field's own variance is exactly sigma^2, axis by axis
    for seed in (0, 1, 2):
        field = FrozenTurbulence.of(seed, DrydenScales.of(6.0, 1.0), 6.0 * EAST)
        variance = 0.5 * (field.amplitudes**2).sum(axis=0)
        assert variance == pytest.approx([sigma_uv**2, sigma_uv**2, sigma_w**2], rel=1e-12)


@pytest.mark.parametrize("separation", ["along", "across"])
@pytest.mark.parametrize(("axis", "name"), [(0, "u"), (1, "v"), (2, "w")])
def test_points_3_m_apart_see_drydens_correlation(gusts_over_seeds, separation, axis, name):
    _, _, length_uv, length_w = _dryden_by_hand()
    # u (east) is longitudinal to a separation along the wind, v (north) to one across it;
    # w is transverse to both. By hand: u along 0.934, u across 0.902, w 0.461.
    longitudinal = (axis, separation) in ((0, "along"), (1, "across"))
    expected = _correlation_at(3.0, length_w if axis == 2 else length_uv, longitudinal)
    other = 1 if separation == "along" else 2
    found = np.corrcoef(gusts_over_seeds[:, 0, axis], gusts_over_seeds[:, other, axis])[0, 1]
    # the sample correlation of n normal pairs has a standard error (1 - rho^2) / sqrt(n - 1)
    # (0.003 for u along, 0.018 for w); the field leaves out 0.02 % of the energy (kL > 1e4)
    tolerance = 4 * (1 - expected**2) / math.sqrt(SEEDS - 1)
    assert found == pytest.approx(expected, abs=tolerance), (name, separation)


def _octave_power(sigma: float, length_m: float, speed: float, axis: int, band) -> float:
    """MIL-F-8785C's one-sided density integrated over a band of frequency (Hz):
    Phi_u = sigma^2 2L / (pi V) / (1 + (L w / V)^2), Phi_v,w = sigma^2 L / (pi V)
    (1 + 3 (L w / V)^2) / (1 + (L w / V)^2)^2, per rad/s."""
    frequency = np.geomspace(*band, 4001)
    x = (length_m * 2 * np.pi * frequency / speed) ** 2
    if axis == 0:
        density = sigma**2 * 2 * length_m / (np.pi * speed) / (1 + x)
    else:
        density = sigma**2 * length_m / (np.pi * speed) * (1 + 3 * x) / (1 + x) ** 2
    return float(np.trapezoid(density * 2 * np.pi, frequency))


def test_a_hovering_vehicle_feels_drydens_spectra():
    # at a fixed point the field passes at the mean speed: each mode is a sine of frequency
    # |k . V| / 2 pi and power a^2 / 2 (what an endless record shows), summed in octave bands
    sigma_uv, sigma_w, length_uv, length_w = _dryden_by_hand()
    edges = 0.015 * 2.0 ** np.arange(9)  # eight octaves, 0.015 to 3.84 Hz
    seeds = range(8)
    found = np.zeros((3, 8))
    for seed in seeds:
        field = FrozenTurbulence.of(seed, DrydenScales.of(6.0, 1.0), 6.0 * EAST)
        frequency = np.abs(field.frequencies) / (2 * np.pi)
        power = 0.5 * field.amplitudes**2
        for band, (low, high) in enumerate(itertools.pairwise(edges)):
            found[:, band] += power[(frequency >= low) & (frequency < high)].sum(axis=0)
    for axis, sigma, length in (
        (0, sigma_uv, length_uv),
        (1, sigma_uv, length_uv),
        (2, sigma_w, length_w),
    ):
        for band, limits in enumerate(itertools.pairwise(edges)):
            if axis == 2 and band < 2:
                continue  # w below 0.06 Hz: a few modes' worth of power, 40-60 % apart per draw
            ratio = found[axis, band] / len(seeds) / _octave_power(sigma, length, 6.0, axis, limits)
            # one draw's octave is within ~25 % of Dryden's (1 std over 400 seeds); eight
            # draws' mean within ~9 %: 30 % is over three of those
            assert ratio == pytest.approx(1.0, abs=0.3), (axis, limits)


def test_the_mean_wind_follows_the_log_law_from_w20():
    field = WindField(WIND, [])
    z0 = 0.05  # the default roughness length: EN 1991-1-4's terrain category II (grass)
    assert WIND.roughness_length_m == z0

    def by_hand(z: float) -> float:  # U(z) = W20 ln(z / z0) / ln(20 ft / z0), held below 10 ft
        return 6.0 * math.log(max(z, 10 * FEET) / z0) / math.log(20 * FEET / z0)

    for height, expected in ((20 * FEET, 6.0), (12.0, 6.846), (20.0, 7.484), (1.0, 5.134)):
        assert field.speed_at(height) == pytest.approx(by_hand(height), rel=1e-12)
        assert field.speed_at(height) == pytest.approx(expected, abs=0.0005)
    assert field.mean(np.array([0.0, 12.0, 12.0])) == pytest.approx(by_hand(12.0) * EAST)
    rough = WindField(replace(WIND, roughness_length_m=0.3), [])  # rougher: a steeper profile
    assert rough.speed_at(3.0) < field.speed_at(3.0) and rough.speed_at(20.0) > field.speed_at(20.0)


WAKE_R = 2.0  # PRIME's R for the deck: thickness 1 m, width 10 m capped at 8: 1^(2/3) 8^(1/3)


def _behind(metres: float) -> float:
    """The gusts' gain ``metres`` behind the deck's lee edge: 1 + 0.7 ((x + R) / R)^(-2/3)."""
    return 1 + 0.7 * ((metres + WAKE_R) / WAKE_R) ** (-2 / 3)


@pytest.mark.parametrize(
    ("point", "speed", "gusts"),
    [
        ((0.0, 0.0, 7.0), 0.3 + 0.7 * math.exp(-5.0 / 2.0), 1 + 0.7 * 20 / 40),  # under, mid-way
        ((-19.5, 0.0, 7.0), 0.3 + 0.7 * math.exp(-0.5 / 2.0), 1 + 0.7 * 0.5 / 40),  # windward
        ((19.5, 0.0, 7.0), 0.3 + 0.7 * math.exp(-0.5 / 2.0), 1 + 0.7 * 39.5 / 40),  # lee edge
        ((-18.5, 0.0, 4.0), 0.3 + 0.7 * math.exp(-1.5 / 2.0), 1 + 0.7 * 1.5 / 40),  # by a pier
        ((21.0, 0.0, 8.5), 1.0, _behind(1.0)),  # behind the lee edge: the wake, no speed-up
        ((26.0, 0.0, 2.0), 1.0, _behind(6.0)),  # further behind, below the deck's height
        ((20.0 + 15 * WAKE_R + 1, 0.0, 8.0), 1.0, 1.0),  # past the wake's reach, 15 R
        ((21.0, 0.0, 9.5), 1.3, 1.3),  # above the deck's top behind it: the edge's speed-up
        ((0.0, 6.0, 8.5), 1.3, 1.3),  # beside the deck's edge
        ((-21.0, 0.0, 8.5), 1.3, 1.3),  # before its windward edge
        ((0.0, 10.0, 8.5), 1.0, 1.0),  # in the open
        ((0.0, 0.0, 12.0), 1.0, 1.0),  # above the deck, beyond the edge band
    ],
)
def test_the_structure_shapes_the_wind_where_the_field_says(point, speed, gusts):
    field = WindField(WIND, BOXES)
    assert field.shaping(np.array(point)) == pytest.approx((speed, gusts))
    assert field.free_stream == pytest.approx([6.0, 0.0, 0.0], abs=1e-12)


def test_the_wake_follows_the_wind_round():
    # a north wind: the lee is south of the deck, and the deck's width across it is 40 m
    # (capped at 8 thicknesses: R is 2 m again); the north side speeds up
    north = WindField(replace(WIND, from_deg=0.0), BOXES)
    assert north.shaping(np.array([0.0, -6.0, 8.5])) == pytest.approx((1.0, _behind(1.0)))
    assert north.shaping(np.array([0.0, 6.0, 8.5])) == pytest.approx((1.3, 1.3))
    # from the south-west: (21, 6) sees the deck's footprint 1.41 m up its upwind line
    skew = WindField(replace(WIND, from_deg=225.0), BOXES)
    assert skew.gust_gain(np.array([21.0, 6.0, 8.5])) == pytest.approx(_behind(math.sqrt(2)))


def test_the_wake_raises_the_turbulence_intensity():
    # the same run's field with the structure and without it: the gusts are the same, times
    # the wake's gain; the intensity (gust sigma over the mean speed) rises more where the
    # deck shelters the mean
    for point, gain, speed in (
        ((21.0, 0.0, 8.5), _behind(1.0), 1.0),  # behind the lee edge
        ((10.0, 0.0, 7.0), 1 + 0.7 * 30 / 40, 0.3 + 0.7 * math.exp(-5.0 / 2.0)),  # under it
    ):
        point = np.array(point)
        shaped, open_air = (VehicleWind.of(WIND, boxes, DT_S, 5) for boxes in (BOXES, []))
        inside = np.vstack([shaped.over_step(point, 125) for _ in range(4)])
        outside = np.vstack([open_air.over_step(point, 125) for _ in range(4)])
        mean_in, mean_out = shaped.field.mean(point), open_air.field.mean(point)
        assert mean_in == pytest.approx(speed * mean_out)
        gusts_in, gusts_out = inside - mean_in, outside - mean_out
        assert gusts_in == pytest.approx(gain * gusts_out, abs=1e-5)
        intensity_in = gusts_in.std(axis=0) / np.linalg.norm(mean_in)
        intensity_out = gusts_out.std(axis=0) / np.linalg.norm(mean_out)
        assert intensity_in == pytest.approx(gain / speed * intensity_out, rel=1e-4)
        assert (intensity_in > 1.5 * intensity_out).all()


def test_one_seed_one_field_whoever_samples_it():
    point = np.array([3.0, 12.0, 6.0])
    first, second = (VehicleWind.of(WIND, BOXES, DT_S, 7) for _ in range(2))
    first.time_s = second.time_s = 30.0
    a, b = first.over_step(point, 125), second.over_step(point, 125)
    assert np.array_equal(a, b) and np.abs(a - a.mean(axis=0)).max() > 0
    other = VehicleWind.of(WIND, BOXES, DT_S, 8)
    other.time_s = 30.0
    assert not np.allclose(other.over_step(point, 125), a)
    # the field is carried by the mean wind: 2 s later, 12 m further east, the same gusts
    field = first.gusts
    assert field.at(point + 12.0 * EAST, 32.0) == pytest.approx(field.at(point, 30.0), abs=1e-9)
    # a step's samples are the field's at each substep's time
    for j in (0, 60, 124):
        assert a[j] - first.field.mean(point) == pytest.approx(
            field.at(point, 30.0 + j * DT_S)[0], abs=1e-5
        )
    # set live to other settings, the field is the same run's: its draws depend on the seed
    gustier = first.blowing(replace(WIND, turbulence=2.0))
    assert gustier.time_s == first.time_s
    assert gustier.gusts.amplitudes == pytest.approx(2 * field.amplitudes, rel=1e-15, abs=0)


def test_still_air_is_still():
    still = VehicleWind.of(replace(WIND, speed_m_s=0.0), BOXES, DT_S, 4)
    assert still.gusts is None and not still.over_step(np.array([0.0, 0.0, 7.0]), 25).any()
    calm = VehicleWind.of(replace(WIND, turbulence=0.0), [], DT_S, 4)  # a mean wind, no gusts
    assert calm.over_step(START, 25) == pytest.approx(np.tile(6.0 * EAST, (25, 1)), rel=0.01)


@pytest.mark.parametrize(
    ("field", "value", "problem"),
    [
        ("shelter", 1.5, "[0, 1]"),
        ("from_deg", 360.0, "[0, 360)"),
        ("roughness_length_m", 0.0, "(0, 0.3]"),
        ("roughness_length_m", 1.0, "terrain categories"),
        ("roughness_length_m", math.nan, "(0, 0.3]"),
        ("wake_gust_gain", 0.5, "raises the turbulence"),
        ("wake_gust_gain", math.inf, "[1, 3]"),
        ("edge_gain", math.nan, "[1, 2]"),
        ("turbulence", math.nan, "turbulence"),
    ],
)
def test_a_wind_that_cannot_be_is_refused(field, value, problem):
    with pytest.raises(FieldProblem, match=field) as refused:
        replace(WIND, **{field: value})
    assert problem in str(refused.value) and "\n" not in str(refused.value)


def test_an_edge_band_wider_than_the_workspace_is_refused():
    with pytest.raises(FieldProblem, match="does not fit the workspace"):
        replace(ALONG.world, wind=replace(WIND, edge_width_m=100.0))

"""The wind around the bridge: Dryden turbulence against its analytic spectra, the structure's
shelter and speed-up where the field says, the same gusts for the same seed, still air as
still, and settings that cannot be."""

from __future__ import annotations

import itertools
import math
from dataclasses import replace

import numpy as np
import pytest
from scipy import signal

from mission.config.errors import FieldProblem
from mission.config.scenario import load_scenario
from mission.world.wind import FEET, DrydenGusts, VehicleWind, WindField

ALONG = load_scenario("along")
WIND = replace(ALONG.world.wind, speed_m_s=6.0, from_deg=270.0)  # a west wind
BOXES = list(ALONG.world.structure.primitives)
DT_S = 0.02


def _analytic(frequency_hz: np.ndarray, sigma: float, length_m: float, speed: float, axis: int):
    """MIL-F-8785C's one-sided density per Hz: Phi(omega) (per rad/s) x 2 pi."""
    omega = 2 * np.pi * frequency_hz
    x = (length_m * omega / speed) ** 2
    if axis == 0:
        per_rad = sigma**2 * 2 * length_m / (np.pi * speed) / (1 + x)
    else:
        per_rad = sigma**2 * length_m / (np.pi * speed) * (1 + 3 * x) / (1 + x) ** 2
    return 2 * np.pi * per_rad


def test_the_gusts_have_drydens_spectra_and_intensities():
    height = 8.0
    gusts = DrydenGusts(WIND, height, DT_S, np.random.default_rng(11))
    samples = gusts.samples(2**18)  # ~87 min at 50 Hz
    along, across, up = samples[:, 0], samples[:, 1], samples[:, 2]  # the wind blows east
    h_ft = height / FEET
    sigma_w = 0.1 * WIND.speed_m_s
    sigma_uv = sigma_w / (0.177 + 0.000823 * h_ft) ** 0.4
    length_uv = h_ft / (0.177 + 0.000823 * h_ft) ** 1.2 * FEET
    for axis, series, sigma, length in (
        (0, along, sigma_uv, length_uv),
        (1, across, sigma_uv, length_uv),
        (2, up, sigma_w, height),
    ):
        frequency, density = signal.welch(series, fs=1 / DT_S, nperseg=2**14)
        ratio = density / np.maximum(
            _analytic(frequency, sigma, length, WIND.speed_m_s, axis), 1e-300
        )
        # over eight octave-wide bands from 0.015 to 3.8 Hz, each band's mean density within
        # 20 % of the analytic one (a band averages tens of bins of ~30 segments each)
        edges = 0.015 * 2.0 ** np.arange(9)
        for low, high in itertools.pairwise(edges):
            in_band = (frequency >= low) & (frequency < high)
            assert np.mean(ratio[in_band]) == pytest.approx(1.0, abs=0.2), (axis, low)
    assert np.std(up) == pytest.approx(sigma_w, rel=0.1)


def test_the_same_seed_gives_the_same_gusts_and_still_air_draws_nothing():
    a = DrydenGusts(WIND, 8.0, DT_S, np.random.default_rng(3)).samples(500)
    b = DrydenGusts(WIND, 8.0, DT_S, np.random.default_rng(3)).samples(500)
    assert np.array_equal(a, b) and np.abs(a).max() > 0
    rng = np.random.default_rng(4)
    still = VehicleWind.of(replace(WIND, speed_m_s=0.0), BOXES, 8.0, DT_S, rng)
    assert not still.over_step(np.array([0.0, 0.0, 7.0]), 25).any()
    assert rng.standard_normal() == np.random.default_rng(4).standard_normal()  # no draw


@pytest.mark.parametrize(
    ("point", "expected"),
    [
        ((0.0, 0.0, 7.0), 0.3 + 0.7 * math.exp(-5.0 / 2.0)),  # under the deck, 5 m in
        ((-19.5, 0.0, 7.0), 0.3 + 0.7 * math.exp(-0.5 / 2.0)),  # under it, 0.5 m in
        ((0.0, 6.0, 8.5), 1.3),  # beside the deck's edge
        ((-18.5, 0.0, 4.0), 0.3 + 0.7 * math.exp(-1.5 / 2.0)),  # by a pier, under the deck
        ((0.0, 10.0, 8.5), 1.0),  # in the open
        ((0.0, 0.0, 12.0), 1.0),  # above the deck, beyond the edge band
    ],
)
def test_the_structure_shelters_and_speeds_the_wind_where_the_field_says(point, expected):
    field = WindField(WIND, BOXES)
    assert field.factor(np.array(point)) == pytest.approx(expected)
    assert field.free_stream == pytest.approx([6.0, 0.0, 0.0], abs=1e-12)


def test_a_pier_in_the_open_speeds_the_wind_beside_it():
    pier = [b for b in BOXES if b.min_m[2] <= 0][:1]
    field = WindField(WIND, pier)
    assert field.factor(np.array([-18.5, 0.0, 4.0])) == pytest.approx(1.3)
    assert field.factor(np.array([-18.5, 0.0, 9.0])) == pytest.approx(1.0)  # above it


def test_a_wind_that_cannot_be_is_refused():
    with pytest.raises(FieldProblem, match="shelter"):
        replace(WIND, shelter=1.5)
    with pytest.raises(FieldProblem, match="from_deg"):
        replace(WIND, from_deg=360.0)
    with pytest.raises(FieldProblem, match="does not fit the workspace"):
        replace(ALONG.world, wind=replace(WIND, edge_width_m=100.0))


def test_the_block_filter_gives_scipys_zero_order_hold_and_lfilter_across_blocks():
    # the independent answer: scipy's own discretisation of the same transfer functions,
    # filtered sample by sample
    speed, height = WIND.speed_m_s, 8.0
    gusts = DrydenGusts(WIND, height, DT_S, np.random.default_rng(5))
    count = 700  # two whole blocks and part of a third
    noise = np.random.default_rng(5).standard_normal((3, count)) * gusts.noise_scale
    ours = np.linalg.solve(gusts.axes, gusts.samples(count).T)  # back to along, across, up
    h_ft = height / FEET
    sigma_w = 0.1 * speed
    sigma_uv = sigma_w / (0.177 + 0.000823 * h_ft) ** 0.4
    length_uv = h_ft / (0.177 + 0.000823 * h_ft) ** 1.2 * FEET
    for axis, (sigma, length) in enumerate(
        [(sigma_uv, length_uv), (sigma_uv, length_uv), (sigma_w, height)]
    ):
        tau = length / speed
        if axis == 0:
            tf = ([sigma * np.sqrt(2 * length / (np.pi * speed))], [tau, 1.0])
        else:
            k = sigma * np.sqrt(length / (np.pi * speed))
            tf = ([k * np.sqrt(3) * tau, k], [tau * tau, 2 * tau, 1.0])
        b, a, _ = signal.cont2discrete(tf, DT_S, method="zoh")
        theirs = signal.lfilter(np.ravel(b), np.ravel(a), noise[axis])
        np.testing.assert_allclose(ours[axis], theirs, rtol=1e-9, atol=1e-12)

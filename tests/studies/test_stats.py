"""The report's statistics against independent answers (scipy's own routines)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from mission.studies.stats import bootstrap_ci, mean_ci, wilcoxon_p


def test_the_mean_interval_is_students_t():
    values = [3.1, 4.7, 2.2, 5.9, 4.4, 3.8]
    mean, half = mean_ci(values)
    low, high = stats.t.interval(
        0.95, len(values) - 1, loc=np.mean(values), scale=stats.sem(values)
    )
    assert mean == pytest.approx(np.mean(values))
    assert (mean - half, mean + half) == pytest.approx((low, high))
    assert mean_ci([2.0]) == (2.0, None) and mean_ci([]) == (None, None)


def test_the_bootstrap_interval_agrees_with_scipys_percentile_bootstrap():
    rng = np.random.default_rng(7)
    differences = list(rng.normal(-12.0, 8.0, 15))
    mean, low, high = bootstrap_ci(differences)
    reference = stats.bootstrap(
        (np.array(differences),),
        np.mean,
        confidence_level=0.95,
        method="percentile",
        n_resamples=20_000,
        random_state=1,
    ).confidence_interval
    width = reference.high - reference.low
    assert mean == pytest.approx(np.mean(differences))
    assert low == pytest.approx(reference.low, abs=0.05 * width)
    assert high == pytest.approx(reference.high, abs=0.05 * width)
    assert bootstrap_ci(differences) == (mean, low, high)  # a fixed seed: the same report


def test_wilcoxon_is_the_exact_signed_rank_test():
    # three pairs, all the same sign: the exact two-sided p is 2 / 2^3
    assert wilcoxon_p([1.0, 2.0, 3.0], [2.0, 4.0, 6.0]) == pytest.approx(0.25)
    assert wilcoxon_p([1.0, 2.0], [1.0, 2.0]) == 1.0
    assert wilcoxon_p([1.0], [2.0]) is None

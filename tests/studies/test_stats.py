"""The report's statistics against independent answers (scipy's own routines)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from mission.studies.stats import EXACT_MAX_PAIRS, bootstrap_ci, mean_ci, wilcoxon_p


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


def test_wilcoxon_is_exact_with_ties_where_scipys_default_approximates():
    """Fifteen pairs all one way, with tied differences (as Along's steps in multipath): the
    exact p is 2 / 2^15; scipy's default (the normal approximation once differences tie)
    gives ten times that."""
    from scipy.stats import wilcoxon

    ac = [10.0] * 15
    nac = [12.0, 12.0, 13.0, 15.0, 15.0, 15.0, 20, 21, 22, 25, 30, 30, 31, 40, 44]
    assert wilcoxon_p(ac, nac) == pytest.approx(2 / 2**15, rel=1e-12)
    assert wilcoxon(ac, nac).pvalue > 5e-4


def _brute_force_p(differences: list[float]) -> float:
    """Every one of the 2^n sign patterns of the non-zero differences, counted."""
    from itertools import product

    from scipy.stats import rankdata

    kept = [d for d in differences if d != 0]
    ranks = rankdata(np.abs(kept))
    observed = sum(r for r, d in zip(ranks, kept, strict=True) if d > 0)
    sums = [sum(r for r, s in zip(ranks, signs, strict=True) if s) for signs in
            product((0, 1), repeat=len(kept))]  # fmt: skip
    below = sum(t <= observed + 1e-9 for t in sums) / len(sums)
    above = sum(t >= observed - 1e-9 for t in sums) / len(sums)
    return min(1.0, 2 * min(below, above))


@pytest.mark.parametrize("seed", range(6))
def test_wilcoxon_matches_every_sign_pattern_counted(seed):
    """Random pairs with ties and zero differences against the enumeration; without ties,
    scipy's exact method agrees too."""
    from scipy.stats import wilcoxon

    rng = np.random.default_rng(seed)
    a = rng.integers(0, 6, 12).astype(float)
    b = rng.integers(0, 6, 12).astype(float)
    assert wilcoxon_p(a.tolist(), b.tolist()) == pytest.approx(_brute_force_p(list(a - b)))
    c = rng.normal(0, 1, 11)
    exact = wilcoxon(c, np.zeros(11), method="exact").pvalue
    assert wilcoxon_p(c.tolist(), [0.0] * 11) == pytest.approx(exact, rel=1e-9)


def test_wilcoxon_approximates_above_the_exact_limit():
    from scipy.stats import wilcoxon

    rng = np.random.default_rng(3)
    a, b = rng.normal(0, 1, EXACT_MAX_PAIRS + 1), rng.normal(0.2, 1, EXACT_MAX_PAIRS + 1)
    approx = wilcoxon(a - b, method="approx").pvalue
    assert wilcoxon_p(a.tolist(), b.tolist()) == pytest.approx(approx)

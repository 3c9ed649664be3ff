"""The statistics of a study's report: a mean's 95 % confidence interval (Student t), a paired
difference's percentile-bootstrap interval, and the paired Wilcoxon signed-rank test (exact,
ties included)."""

from __future__ import annotations

import math
import statistics

import numpy as np

BOOTSTRAP_RESAMPLES = 10_000
BOOTSTRAP_SEED = 0  # the report is the same each time it is written


def mean_ci(values: list[float], level: float = 0.95) -> tuple[float | None, float | None]:
    """(mean, half-width of its Student-t interval); the half-width is None below 2 values."""
    if not values:
        return None, None
    mean = statistics.fmean(values)
    if len(values) < 2:
        return mean, None
    from scipy.stats import t

    half = (
        t.ppf(0.5 + level / 2, len(values) - 1) * statistics.stdev(values) / math.sqrt(len(values))
    )
    return mean, float(half)


def bootstrap_ci(
    differences: list[float], level: float = 0.95
) -> tuple[float | None, float | None, float | None]:
    """(mean, low, high): the mean paired difference and its percentile-bootstrap interval
    (resampling the pairs; fixed seed)."""
    if not differences:
        return None, None, None
    values = np.asarray(differences, dtype=float)
    if len(values) < 2:
        return float(values.mean()), None, None
    rng = np.random.default_rng(BOOTSTRAP_SEED)
    picks = rng.integers(0, len(values), size=(BOOTSTRAP_RESAMPLES, len(values)))
    means = values[picks].mean(axis=1)
    tail = 100 * (1 - level) / 2
    low, high = np.percentile(means, [tail, 100 - tail])
    return float(values.mean()), float(low), float(high)


EXACT_MAX_PAIRS = 200  # above: the normal approximation (the exact one's table grows as n^3)
WILCOXON_METHOD = (
    "two-sided paired Wilcoxon signed-rank test, exact: the signed-rank sum's distribution "
    "over every sign pattern (2^n), with mid-ranks for tied differences and zero differences "
    f"dropped; the normal approximation above {EXACT_MAX_PAIRS} pairs"
)


def wilcoxon_p(a: list[float], b: list[float]) -> float | None:
    """Two-sided paired Wilcoxon signed-rank p-value (:data:`WILCOXON_METHOD`); 1.0 when every
    pair is equal; None below two pairs.

    Exact with ties, where scipy's default falls back to the normal approximation (15 pairs
    all one way: 2 / 2^15 = 6.1e-5, not the 7e-4 the approximation gives): under the null
    hypothesis each difference's sign is + or - with even odds, so the sum of the positive
    differences' ranks is a sum of independent terms 0 or rank, whose distribution a
    convolution over the (doubled, so whole) mid-ranks gives exactly."""
    if len(a) < 2:
        return None
    differences = np.asarray(a, dtype=float) - np.asarray(b, dtype=float)
    differences = differences[differences != 0]
    if len(differences) == 0:
        return 1.0
    if len(differences) > EXACT_MAX_PAIRS:
        from scipy.stats import wilcoxon

        return float(wilcoxon(differences, method="approx").pvalue)
    from scipy.stats import rankdata

    doubled = np.rint(2 * rankdata(np.abs(differences))).astype(int)  # mid-ranks are halves
    counts = np.zeros(int(doubled.sum()) + 1)
    counts[0] = 1.0
    for rank in doubled:  # each term: 0 or rank, with even odds
        counts[rank:] = counts[rank:] + counts[: len(counts) - rank]
    probability = counts / counts.sum()
    positive = int(doubled[differences > 0].sum())
    below = probability[: positive + 1].sum()
    above = probability[positive:].sum()
    return float(min(1.0, 2 * min(below, above)))

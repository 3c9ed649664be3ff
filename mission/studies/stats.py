"""The statistics of a study's report: a mean's 95 % confidence interval (Student t), a paired
difference's percentile-bootstrap interval, and the paired Wilcoxon signed-rank test."""

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


def wilcoxon_p(a: list[float], b: list[float]) -> float | None:
    """Two-sided paired Wilcoxon signed-rank p-value; 1.0 when every pair is equal; None
    below two pairs."""
    from scipy.stats import wilcoxon

    if len(a) < 2:
        return None
    if all(x == y for x, y in zip(a, b)):
        return 1.0
    return float(wilcoxon(a, b).pvalue)

"""The chi-square arithmetic of the integrity monitor, in closed form (no scipy at a ground
station's start): the gate of a test of ``dof`` degrees of freedom at a false-alarm rate, and,
for three, the minimal detectable bias at a missed-detection rate.

A test statistic T = nu^T S^-1 nu of a 3-vector innovation nu with covariance S is chi-square
with 3 degrees of freedom when there is no fault; a bias b in nu makes it non-central with
lambda = b^T S^-1 b. For 3 degrees of freedom both distributions have closed forms (T is the
squared length of a 3-D normal vector): with r = sqrt(x) and a = sqrt(lambda),

    P(T <= x)            = erf(r / sqrt 2) - sqrt(2 / pi) r exp(-x / 2)
    P(T <= x; lambda)    = Phi(r - a) - Phi(-r - a) - (phi(r - a) - phi(r + a)) / a.

For an even number of degrees of freedom 2m (a sum of m cycles' statistics is not, but the sum
of k three-dof statistics has 3k, handled by the series below) the survival function is the
Poisson sum exp(-x/2) sum_{j<m} (x/2)^j / j!; for odd 2m+1 it adds to erfc the same series in
half-integer steps. :func:`survival` covers every integer.
"""

from __future__ import annotations

import math


def survival(x: float, dof: int) -> float:
    """P(T > x) for T chi-square with ``dof`` (>= 1) degrees of freedom."""
    if x <= 0:
        return 1.0
    half = x / 2
    if dof % 2 == 0:  # exp(-x/2) sum_{j < dof/2} (x/2)^j / j!
        term = total = math.exp(-half)
        for j in range(1, dof // 2):
            term *= half / j
            total += term
        return min(total, 1.0)
    # odd: erfc(sqrt(x/2)) + exp(-x/2) sum_{j=1}^{(dof-1)/2} (x/2)^(j-1/2) / Gamma(j + 1/2)
    total = math.erfc(math.sqrt(half))
    term = math.exp(-half) * math.sqrt(half) / math.gamma(1.5)
    for j in range(1, (dof - 1) // 2 + 1):
        total += term
        term *= half / (j + 0.5)
    return min(total, 1.0)


def gate(false_alarm: float, dof: int = 3) -> float:
    """The x at which a no-fault statistic exceeds x with probability ``false_alarm``."""
    return _solve_falling(lambda x: survival(x, dof), false_alarm, float(dof))


def _solve_falling(function, target: float, start: float) -> float:
    """The x >= 0 at which a falling ``function`` crosses ``target``, by bisection to a
    relative 1e-12 (each is solved once per run)."""
    low, high = 0.0, start
    while function(high) > target:
        high *= 2
    for _ in range(200):
        middle = (low + high) / 2
        if function(middle) > target:
            low = middle
        else:
            high = middle
        if high - low < 1e-12 * high:
            break
    return (low + high) / 2


def _phi(x: float) -> float:
    return math.exp(-x * x / 2) / math.sqrt(2 * math.pi)


def _cdf_normal(x: float) -> float:
    return 0.5 * math.erfc(-x / math.sqrt(2))


def noncentral_cdf_3(x: float, lam: float) -> float:
    """P(T <= x) for T non-central chi-square, 3 degrees of freedom, non-centrality lam."""
    if x <= 0:
        return 0.0
    r = math.sqrt(x)
    if lam <= 0:
        return 1.0 - survival(x, 3)
    a = math.sqrt(lam)
    value = _cdf_normal(r - a) - _cdf_normal(-r - a) - (_phi(r - a) - _phi(r + a)) / a
    return min(max(value, 0.0), 1.0)


def detectable_noncentrality(false_alarm: float, missed_detection: float) -> float:
    """lambda* at which a 3-dof test at ``false_alarm``'s gate misses with probability
    ``missed_detection``: a bias b is detected at least that often where b^T S^-1 b >= lambda*."""
    threshold = gate(false_alarm, 3)
    return _solve_falling(lambda lam: noncentral_cdf_3(threshold, lam), missed_detection, threshold)

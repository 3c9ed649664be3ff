"""Selective fusion for the work UAV (paper 3.2.1) and feedback to each support (3.2.2).

Each support n with a fix p_n and a valid observation r_n gives the likelihood
N(mu_n, Sigma_n), mu_n = p_n + r_n, Sigma_n = Sigma_GNSS(p_n) + Sigma_r(r_n). Supports whose
likelihoods correlate (Pearson, over a broad particle set around the predicted position) with
at least half of the contributing supports (``agreement: paper``: half of all N) form the
consistent set S; xhat is the candidate particle maximising sum_{n in S} log f(x; mu_n,
Sigma_n). Interpretations: docs/model.md, "Selective fusion (3.2.1) and feedback (3.2.2)" and
"Supports counted in the agreement test".
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ground_station.state.station_state import StationState
from mission.config.settings import FusionSettings


@dataclass(frozen=True)
class SupportMeasurement:
    """What the ground station has from one support this cycle (ENU)."""

    name: str
    fix_m: np.ndarray | None
    sigma_gnss_m2: np.ndarray | None
    relative_m: np.ndarray | None
    sigma_relative_m2: np.ndarray | None
    reported_m2: np.ndarray | None = None  # the receiver's own accuracy (GPS_RAW_INT)
    belief_m: np.ndarray | None = None  # where its autopilot believes it is (LOCAL_POSITION_NED)

    @property
    def sigma_gnss_tested_m2(self) -> np.ndarray | None:
        """Sigma_GNSS as the integrity monitor tests it: the model's, or the receiver's own
        where that says it is worse (larger trace)."""
        model, reported = self.sigma_gnss_m2, self.reported_m2
        if model is None or reported is None or np.trace(reported) <= np.trace(model):
            return model
        return reported

    @property
    def contributes(self) -> bool:
        """True with both a fix and a valid observation."""
        return self.fix_m is not None and self.relative_m is not None

    @property
    def mu(self) -> np.ndarray:
        """p_n + r_n."""
        assert self.fix_m is not None and self.relative_m is not None
        return self.fix_m + self.relative_m

    @property
    def sigma(self) -> np.ndarray:
        """Sigma_GNSS(p_n) + Sigma_r(r_n)."""
        assert self.sigma_gnss_m2 is not None and self.sigma_relative_m2 is not None
        return self.sigma_gnss_m2 + self.sigma_relative_m2


@dataclass(frozen=True)
class FusionResult:
    """The outcome of one fusion: xhat (None when blind), S, and how it was reached."""

    xhat: np.ndarray | None
    consistent: tuple[str, ...]
    contributing: tuple[str, ...]
    fallback: bool
    rho: np.ndarray
    densities: tuple[LogDensity, ...]  # log f(x; mu_n, Sigma_n) of the supports in S

    @property
    def blind(self) -> bool:
        """No support contributed: no new estimate."""
        return self.xhat is None

    def log_p(self, x: np.ndarray) -> np.ndarray:
        """log P(x) up to the constant alpha: sum over S of log f(x; mu_n, Sigma_n)."""
        x = np.atleast_2d(x)
        if not self.densities:
            return np.zeros(len(x))
        return sum(iter(log_densities(self.densities, x)), start=np.zeros(len(x)))


@dataclass(frozen=True)
class LogDensity:
    """log N(x; mu, sigma) with sigma's Cholesky factor and log-determinant computed once (a
    cycle evaluates each support's density several times)."""

    mu: np.ndarray
    factor: np.ndarray
    log_det: float

    @classmethod
    def of(cls, mu: np.ndarray, sigma: np.ndarray) -> LogDensity:
        """The density of N(mu, sigma)."""
        factor = np.linalg.cholesky(sigma)
        return cls(mu, factor, 2.0 * np.sum(np.log(np.diag(factor))))

    def __call__(self, x: np.ndarray) -> np.ndarray:
        """log N(x; mu, sigma) for rows of x (a scalar for one point given as a vector)."""
        x = np.asarray(x, dtype=float)
        if x.ndim == 1:
            return log_densities((self,), x[None])[0][0]
        return log_densities((self,), x)[0]


def log_densities(densities: tuple[LogDensity, ...] | list[LogDensity], x: np.ndarray):
    """(k, n): each density's log N at the rows of x, the k triangular systems solved in one
    call (each as it is alone: the same values)."""
    factors = np.array([density.factor for density in densities])
    offsets = np.array([(x - density.mu).T for density in densities])
    z = np.linalg.solve(factors, offsets)
    log_det = np.array([density.log_det for density in densities])
    return -0.5 * (np.sum(z * z, axis=1) + log_det[:, None] + 3 * np.log(2 * np.pi))


def fuse(
    state: StationState,
    supports: list[SupportMeasurement],
    settings: FusionSettings,
    rng: np.random.Generator,
) -> tuple[FusionResult, dict[str, float | None]]:
    """Step 2 of the control cycle: selective fusion for xhat around the position predicted
    from the last command (blind: xhat becomes that prediction), then feedback to each
    support's yhat_n; updates ``state`` and returns the fusion and each support's beta_n."""
    predicted = state.xhat + state.last_work_command
    fusion = selective_fusion(supports, predicted, settings, rng)
    # Blind, the work UAV's estimate is dead-reckoned: where its last command took it (the
    # position its autopilot believes, which it then holds: ground_station.control.plan).
    state.xhat = predicted if fusion.xhat is None else fusion.xhat
    betas: dict[str, float | None] = {}
    for support in supports:
        previous = state.yhat[support.name]
        moved = state.last_support_command.get(support.name, np.zeros(3))
        result = support_feedback(support, fusion, previous, moved)
        state.yhat[support.name] = result.yhat
        betas[support.name] = result.beta
    return fusion, betas


def selective_fusion(
    supports: list[SupportMeasurement],
    predicted: np.ndarray,
    settings: FusionSettings,
    rng: np.random.Generator,
) -> FusionResult:
    """Estimate the work UAV's position from the consistent supports."""
    contributing = [s for s in supports if s.contributes]
    names = tuple(s.name for s in contributing)
    if not contributing:
        return FusionResult(None, (), (), False, np.zeros((0, 0)), ())
    broad = predicted + settings.broad_sigma_m * rng.standard_normal((settings.broad_particles, 3))
    local = [
        rng.multivariate_normal(s.mu, s.sigma, settings.local_particles, method="cholesky")
        for s in contributing
    ]
    densities = [LogDensity.of(s.mu, s.sigma) for s in contributing]
    rho = correlation_matrix(list(log_densities(densities, broad)))
    agree = (rho > settings.rho_threshold).sum(axis=1)
    voters = len(supports) if settings.agreement == "paper" else len(contributing)
    in_s = [i for i, count in enumerate(agree) if count >= voters / 2]
    fallback = not in_s
    if fallback:
        in_s = list(range(len(contributing)))
    particles = np.vstack([broad, *local])
    chosen = tuple(densities[i] for i in in_s)
    score = sum(iter(log_densities(chosen, particles)))
    xhat = particles[int(np.argmax(score))]
    consistent = tuple(contributing[i].name for i in in_s)
    return FusionResult(xhat, consistent, names, fallback, rho, chosen)


def correlation_matrix(log_densities: list[np.ndarray]) -> np.ndarray:
    """Pearson correlation between density vectors given as logs (scale-free, no underflow).

    A vector with no spread (every density zero in floating point) correlates with nothing.
    """
    n = len(log_densities)
    values = np.array([np.exp(v - np.max(v)) for v in log_densities])
    centred = values - values.mean(axis=1, keepdims=True)
    norms = np.sqrt(np.sum(centred * centred, axis=1))
    rho = np.eye(n)
    for i in range(n):
        for j in range(i + 1, n):
            if norms[i] > 0 and norms[j] > 0:
                rho[i, j] = rho[j, i] = float(centred[i] @ centred[j] / (norms[i] * norms[j]))
            else:
                rho[i, j] = rho[j, i] = 0.0
    return rho


@dataclass(frozen=True)
class Feedback:
    """yhat_n and beta_n for one support (beta None when yhat came from a fallback rule)."""

    yhat: np.ndarray
    beta: float | None


def support_feedback(
    support: SupportMeasurement,
    fusion: FusionResult,
    previous_yhat: np.ndarray,
    last_command: np.ndarray,
) -> Feedback:
    """Feed xhat back to a support's estimate (3.2.2), with the fallbacks of docs/model.md,
    "Selective fusion (3.2.1) and feedback (3.2.2)"."""
    if support.fix_m is None:
        return Feedback(previous_yhat + last_command, None)
    if support.relative_m is None or fusion.xhat is None:
        return Feedback(support.fix_m.copy(), None)
    mu = support.mu
    log_at_mu, log_at_xhat = fusion.log_p(np.vstack([mu, fusion.xhat]))
    beta = float(1.0 / (1.0 + np.exp(np.clip(log_at_mu - log_at_xhat, -700, 700))))
    yhat = beta * fusion.xhat + (1 - beta) * mu - support.relative_m
    return Feedback(yhat, beta)

"""3x3 symmetric positive-definite algebra in plain floats: the monitor inverts a dozen 3x3
covariances a cycle, and numpy.linalg's per-call overhead (15-20 us) is ten times the
arithmetic. Cofactors over the determinant, exact for the well-conditioned covariances the
monitor meets (their condition numbers stay under 1e4)."""

from __future__ import annotations

import numpy as np


def inverse3(matrix: np.ndarray) -> np.ndarray:
    """The inverse of a 3x3 matrix (ValueError where it is singular)."""
    (a, b, c), (d, e, f), (g, h, i) = matrix.tolist()
    co_a, co_b, co_c = e * i - f * h, f * g - d * i, d * h - e * g
    det = a * co_a + b * co_b + c * co_c
    if det == 0.0:
        raise ValueError("singular 3x3 matrix")
    inv = 1.0 / det
    return np.array(
        [
            [co_a * inv, (c * h - b * i) * inv, (b * f - c * e) * inv],
            [co_b * inv, (a * i - c * g) * inv, (c * d - a * f) * inv],
            [co_c * inv, (b * g - a * h) * inv, (a * e - b * d) * inv],
        ]
    )


def quadratic3(vector: np.ndarray, inverse: np.ndarray) -> float:
    """v^T M v for a 3-vector and a 3x3 matrix (M the inverse of a covariance)."""
    x, y, z = vector.tolist()
    (a, b, c), (d, e, f), (g, h, i) = inverse.tolist()
    return x * (a * x + b * y + c * z) + y * (d * x + e * y + f * z) + z * (g * x + h * y + i * z)

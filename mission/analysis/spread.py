"""The mean, 95th percentile and maximum of a run's values, as summary.json reports them."""

from __future__ import annotations

import numpy as np


def spread(values: list[float]) -> dict[str, float | None]:
    """Mean, p95 and max rounded to 0.1 mm (all None without values)."""
    if not values:
        return {"mean": None, "p95": None, "max": None}
    return {
        "mean": round(float(np.mean(values)), 4),
        "p95": round(float(np.percentile(values, 95)), 4),
        "max": round(float(np.max(values)), 4),
    }

"""Reading a saved recording back with Rerun's own Python API (``rerun.chunk.RrdReader``)."""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path

import numpy as np

from mission.viewer.frame import TIMELINE


def read_rrd(path: Path) -> dict[str, dict[str, list]]:
    """Per entity path, per column (the time line, each component), every row's value, in
    time order (static rows have no time)."""
    from rerun.chunk import RrdReader

    columns: dict[str, dict[str, list]] = defaultdict(lambda: defaultdict(list))
    for chunk in RrdReader(path).stream():
        batch = chunk.to_record_batch()
        for name in batch.schema.names:
            column = batch.column(name)
            if name == TIMELINE:  # durations, as integer nanoseconds
                columns[chunk.entity_path][name].extend(column.cast("int64").to_pylist())
            elif ":" in name:  # a component (the other time lines are the logger's clock)
                columns[chunk.entity_path][name].extend(column.to_pylist())
    for entity in columns.values():
        if TIMELINE in entity:
            order = np.argsort(entity[TIMELINE], kind="stable")
            for name, values in entity.items():
                if len(values) == len(order):
                    entity[name] = [values[i] for i in order]
    return columns


def times(entity: dict[str, list]) -> np.ndarray:
    """An entity's simulated times, seconds."""
    return np.array(entity[TIMELINE], dtype=float) / 1e9


def points(entity: dict[str, list]) -> np.ndarray:
    """(rows, 3): the one position of each row."""
    return np.array([row[0] for row in entity["Points3D:positions"]], dtype=float).reshape(-1, 3)

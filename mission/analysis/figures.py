"""Saving figures: the format follows the file's suffix, the file is written atomically."""

from __future__ import annotations

from pathlib import Path

from mission.procs.atomic import write_atomically

FIGURE_SUFFIXES = (".png", ".pdf", ".svg")


def save_figure(fig, path: Path, dpi: int = 100) -> None:
    """Write ``fig`` to ``path`` as PNG, PDF or SVG by its suffix, then close it."""
    import matplotlib.pyplot as plt

    kind = Path(path).suffix.lower().lstrip(".") or "png"
    write_atomically(Path(path), lambda temp: fig.savefig(temp, dpi=dpi, format=kind))
    plt.close(fig)

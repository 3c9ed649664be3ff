"""What a run's figures mark on their time axes and in their views: each change a vehicle
reported (summary.json's ``events``: a scripted fault, a parameter the ground station set, a
failure injected by command) and each contact or crash it reported (``safety.contacts``)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from matplotlib.lines import Line2D
from matplotlib.transforms import blended_transform_factory

from mission.analysis.trace import RunTrace
from mission.link.vehicle_identity import VehicleIdentity

# kind: (the legend's name for it, colour, line style on a time axis, marker in a view)
KINDS = {
    "scenario": ("scripted fault, its start or end (faults:)", "darkorange", "--", "^"),
    "parameter": ("parameter set by the ground station", "teal", ":", "^"),
    "command": ("failure injected by command", "saddlebrown", "-.", "^"),
    "contact": ("contact (the vehicle flew on)", "red", "-", "X"),
    "crash": ("crash (the run stopped)", "black", "-", "X"),
}


@dataclass(frozen=True)
class Mark:
    """One moment a figure marks: when, what kind, which vehicle, what it was, where."""

    t: float
    kind: str  # a key of KINDS
    system: int  # the vehicle's MAVLink system id (1: the work UAV)
    what: str  # "SIM_GPS1_GLTCH_X=2e-05", "gps off", "structure"
    at_m: np.ndarray | None  # where, when known (a contact's)

    @property
    def text(self) -> str:
        """Short enough to stand beside a line: ``support 1: gps off``."""
        vehicle = "work UAV" if self.system == 1 else f"support {self.system - 1}"
        what = f"touched {self.what}" if self.kind in ("contact", "crash") else self.what
        return f"{vehicle}: {what}"


def run_marks(trace: RunTrace) -> list[Mark]:
    """The run's events and contacts as marks, by time."""
    marks = [
        Mark(e["t"], e["source"], _system(e["vehicle"]), e["event"], None)
        for e in trace.events
        if e.get("source") in KINDS
    ]
    marks += [
        Mark(
            c["t"],
            "crash" if c["crash"] else "contact",
            _system(c["vehicle"]),
            c["with"],
            np.array(c["at_m"], dtype=float),
        )
        for c in trace.contacts
    ]
    return sorted(marks, key=lambda m: (m.t, m.system, m.kind))


def _system(vehicle: str) -> int:
    return VehicleIdentity.parse(vehicle).system_id


def legend_handles(marks: list[Mark], line: bool) -> list[Line2D]:
    """One legend entry per kind of mark present: its line (a time axis) or marker (a view)."""
    handles = []
    for kind in dict.fromkeys(m.kind for m in marks):
        name, colour, style, marker = KINDS[kind]
        if line:
            handles.append(Line2D([], [], color=colour, linestyle=style, label=name))
        else:
            handles.append(
                Line2D(
                    [],
                    [],
                    color=colour,
                    marker=marker,
                    linestyle="",
                    markersize=9,
                    markeredgecolor="k",
                    label=name,
                )
            )
    return handles


def mark_times(ax, marks: list[Mark]) -> list[Line2D]:
    """A vertical line at each mark, what it was written along it; the legend's handles."""
    along = blended_transform_factory(ax.transData, ax.transAxes)
    said: dict[tuple[float, str], list[str]] = {}
    for mark in marks:
        said.setdefault((mark.t, mark.kind), []).append(mark.text)
    for (t, kind), texts in said.items():
        _, colour, style, _ = KINDS[kind]
        ax.axvline(t, color=colour, linestyle=style, lw=1.2)
        ax.annotate(
            f"{'; '.join(texts)} (t = {t:g} s)",
            (t, 0.97),
            xycoords=along,
            xytext=(-3, 0),
            textcoords="offset points",
            rotation=90,
            va="top",
            ha="right",
            fontsize=7,
            color=colour,
            bbox={"facecolor": "white", "alpha": 0.75, "edgecolor": "none", "pad": 1},
        )
    return legend_handles(marks, line=True)


def mark_places(ax, marks: list[Mark], trace: RunTrace, axes: tuple[int, ...]) -> None:
    """Each mark where it happened, on a view of the coordinates ``axes`` (two, or three for
    a 3-D view): a contact where the vehicle reported it, a change where its vehicle was."""
    for mark in marks:
        where = mark.at_m
        if where is None:
            positions, known = trace.truth_at(mark.system, [mark.t])
            if not known[0]:
                continue
            where = positions[0]
        _, colour, _, marker = KINDS[mark.kind]
        ax.plot(
            *(where[[i]] for i in axes),
            marker=marker,
            color=colour,
            markersize=10,
            markeredgecolor="k",
            linestyle="",
            zorder=5,
        )

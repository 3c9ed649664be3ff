"""Where a run's CPU seconds go: py-spy's samples of every process of a run, by process and
by function.

Record a run (py-spy is the ``profile`` extra; it samples the processes from outside, so the
run's own timing barely changes)::

    py-spy record --rate 250 --subprocesses --format raw -o run.txt -- \\
        "$(python -c 'import sys; print(sys.executable)')" -m mission run along --out logs/p
    python -m mission.bench.profile run.txt --rate 250

Only samples of a running thread count (py-spy's default), so samples / rate estimates CPU
seconds. Forked processes carry their parent's stack, so each sample is attributed to the
last process its stack names, and that process to a role by its entry frame: a vehicle, the
ground station, its MPC helper, or the orchestrator (start-up, the run, the analysis).
"""

from __future__ import annotations

import argparse
import re
from collections import Counter, defaultdict
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

ROLE_FRAMES = (  # the first of these a process's stack holds says what it is
    ("serve_descriptors (ground_station/support_mpc/helper.py", "mpc helper"),
    ("entry_point (ground_station/cli.py", "ground station"),
    ("entry_point (vehicle_sim/cli.py", "vehicle"),
)
PHASE_FRAMES = (  # the orchestrator's phases, by the frame its stack holds
    ("_summary (mission/runs/orchestrator.py", "orchestrator: analysis"),
    ("_start_processes (mission/runs/orchestrator.py", "orchestrator: start-up"),
    ("_find_and_load (<frozen importlib._bootstrap>", "orchestrator: start-up"),
)
_PROCESS = re.compile(r"^process (\d+):")
_LINE = re.compile(r" \((.+?):\d+\)$")


@dataclass
class Profile:
    """Samples by role, the processes of each role, and samples by function (self and
    inclusive) within each role."""

    samples: Counter = field(default_factory=Counter)
    processes: dict[str, set[str]] = field(default_factory=lambda: defaultdict(set))
    own: dict[str, Counter] = field(default_factory=lambda: defaultdict(Counter))
    inclusive: dict[str, Counter] = field(default_factory=lambda: defaultdict(Counter))


def read_profile(lines: Iterable[str]) -> Profile:
    """A py-spy raw (collapsed stacks) recording, attributed."""
    stacks = []
    role_of: dict[str, str] = {}
    for line in lines:
        if not line.strip():
            continue
        stack, count = line.rsplit(" ", 1)
        frames = stack.split(";")
        last = max(i for i, frame in enumerate(frames) if _PROCESS.match(frame))
        pid = _PROCESS.match(frames[last]).group(1)  # type: ignore[union-attr]
        frames = [_function(frame) for frame in frames[last + 1 :]]
        stacks.append((pid, frames, int(count)))
        role = _role(frames, ROLE_FRAMES)
        if role is not None:
            role_of.setdefault(pid, role)
    profile = Profile()
    for pid, frames, count in stacks:
        role = role_of.get(pid) or _role(frames, PHASE_FRAMES) or "orchestrator: the run"
        profile.samples[role] += count
        profile.processes[role].add(pid)
        if frames:
            profile.own[role][frames[-1]] += count
        for function in set(frames):
            profile.inclusive[role][function] += count
    return profile


def _function(frame: str) -> str:
    """``name (file)`` without the line number."""
    return _LINE.sub(lambda match: f" ({match.group(1)})", frame)


def _role(frames: Sequence[str], table: Sequence[tuple[str, str]]) -> str | None:
    for prefix, role in table:
        if any(frame.startswith(prefix) for frame in frames):
            return role
    return None


def report(profile: Profile, rate_hz: float, top: int = 8) -> str:
    """Markdown: CPU seconds by role, then each role's busiest functions (self time)."""
    total = sum(profile.samples.values())
    lines = ["| process | count | CPU s | share |", "|---|---|---|---|"]
    for role, count in profile.samples.most_common():
        lines.append(
            f"| {role} | {len(profile.processes[role])} | {count / rate_hz:.2f} | "
            f"{100 * count / total:.1f} % |"
        )
    lines.append(f"| all | | {total / rate_hz:.2f} | 100 % |")
    for role, count in profile.samples.most_common():
        lines += ["", f"**{role}**, self time:", ""]
        for function, own in profile.own[role].most_common(top):
            lines.append(f"- {100 * own / count:.1f} % `{function}`")
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    """Print the report of a recording."""
    parser = argparse.ArgumentParser(prog="python -m mission.bench.profile", description=__doc__)
    parser.add_argument("recording", type=Path, help="py-spy record --format raw output")
    parser.add_argument("--rate", type=float, default=100.0, help="the recording's --rate")
    parser.add_argument("--top", type=int, default=8, help="functions shown per process")
    args = parser.parse_args(argv)
    with args.recording.open() as recording:
        print(report(read_profile(recording), args.rate, args.top))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

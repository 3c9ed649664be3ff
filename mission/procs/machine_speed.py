"""How fast this machine is right now: the CPU seconds of a fixed pure-Python loop (a shared
VM's speed drifts by tens of per cent within hours). The benchmarks report it beside every
figure; a study scales its duration estimate by it. Also: the CPU seconds this process's
children have used."""

from __future__ import annotations

import statistics
import time

REFERENCE_LOOP_S = 0.146  # the machine the benchmarks' targets were set on


def python_loop_s(repeats: int = 5) -> float:
    """The median CPU seconds of ``sum(range(10_000_000))`` over ``repeats``."""
    times = []
    for _ in range(repeats):
        start = time.process_time()
        sum(range(10_000_000))
        times.append(time.process_time() - start)
    return statistics.median(times)


def children_cpu_s() -> float:
    """User and system CPU seconds of every process this one has waited for (a run's
    processes are waited for by theirs, so they count too)."""
    import resource

    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime

"""``mission bench``: the benchmarks, with their targets."""

from __future__ import annotations

import argparse
import json


def add_parser(commands) -> None:
    """``mission bench``'s arguments."""
    parser = commands.add_parser("bench", help="run the benchmarks and print their medians")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument(
        "--only",
        action="append",
        choices=[
            "world",
            "vehicle",
            "gcs",
            "margins",
            "roles",
            "integrity",
            "multipath",
            "run",
            "floor",
            "study",
            "view",
        ],
        help="run only this group (repeatable)",
    )
    parser.set_defaults(handler=bench)


def bench(args: argparse.Namespace) -> int:
    """``mission bench``."""
    from mission.bench.result import format_table
    from mission.bench.suite import run_benchmarks
    from mission.procs.interrupts import StopRequest

    with StopRequest():  # Ctrl-C stops it even where it was started as a background job
        results = run_benchmarks(args.only)
    if args.json:
        print(json.dumps({r.name: r.value for r in results}))
    else:
        print(format_table(results))
    return 0

"""``mission study FILE --verify N|all --against DIR``: a committed study's rows made again
with today's code and compared (:mod:`mission.studies.verify`)."""

from __future__ import annotations

import argparse
from pathlib import Path

from mission.api.study_checks import checked_engine
from mission.config.errors import InputError
from mission.procs.interrupts import StopRequest


def add_verify_arguments(parser: argparse.ArgumentParser) -> None:
    """``--verify``, ``--against`` and ``--draw-seed``."""
    parser.add_argument(
        "--verify",
        metavar="N|all",
        help="make N rows (drawn at random, listed) or all of --against's results again with "
        "today's code, the canary first; compare every column but the timings; exit 1 on any "
        "difference (the runs go to --out, default results/NAME-verify)",
    )
    parser.add_argument(
        "--against", type=Path, metavar="DIR", help="with --verify: the committed study's folder"
    )
    parser.add_argument(
        "--draw-seed",
        type=int,
        metavar="S",
        help="with --verify N: the seed of the draw of rows (default: 0)",
    )


def verify_count(text: str) -> int | None:
    """``--verify``'s value: a number of rows (>= 1), or None for all."""
    if text == "all":
        return None
    try:
        count = int(text)
    except ValueError:
        count = 0
    if count < 1:
        raise InputError("command line", "--verify", f"must be a number >= 1 or all, got {text!r}")
    return count


def verify_command(spec, args: argparse.Namespace) -> int:
    """Check everything, then verify on the chosen engine; 0 when every compared row (and the
    canary) agrees, 1 otherwise."""
    from mission.studies.study import plan_runs
    from mission.studies.verify import committed_rows, run_verify

    count = verify_count(args.verify)
    if args.against is None:
        raise InputError("command line", "--against", "--verify needs the committed study's DIR")
    if args.keep != "all":
        raise InputError("command line", "--keep", "is for a study's own runs, not --verify's")
    committed_rows(args.against, plan_runs(spec))  # every row a run of the study, or say which
    out = args.out or Path("results") / f"{spec.name}-verify"
    if out.resolve() == args.against.resolve():
        raise InputError(
            "command line", "--out", "must not be --against (nothing is written there)"
        )
    engine = checked_engine(spec, out, args.jobs, args.runs, args.engine, args.address)
    try:
        with StopRequest():
            outcome = run_verify(
                spec, args.against, count, out, engine, runs_dir=args.runs, seed=args.draw_seed or 0
            )
    except KeyboardInterrupt:
        print(f"verification interrupted; the runs made are kept in {out}")
        return 130
    print("\n".join(outcome.lines))
    return 0 if outcome.agrees else 1

"""``python -m mission``: the project's main command line, one module per command
(:mod:`mission.commands`)."""

from __future__ import annotations

from collections.abc import Sequence

from mission.commands import analyze, batch, bench, plan, run, study, vehicle, view, world
from mission.procs.command_line import OneLineArgumentParser, program_name, run_guarded

COMMANDS = (world, vehicle, plan, analyze, view, bench, run, batch, study)  # in --help's order


def build_parser() -> OneLineArgumentParser:
    """The argument parser with every command."""
    parser = OneLineArgumentParser(
        prog=program_name("mission", "mission"),
        description="Run, batch, analyse and inspect missions of the bridge-inspection UAVs.",
    )
    parser.add_argument(
        "--version", action="version", version=f"%(prog)s {_version_text()}", help="say the version"
    )
    commands = parser.add_subparsers(
        dest="command", required=True, metavar="COMMAND", parser_class=OneLineArgumentParser
    )
    for command in COMMANDS:
        command.add_parser(commands)
    return parser


def _version_text() -> str:
    """The package's version, and the commit where this is a git checkout."""
    from mission.procs.provenance import code_identity

    code = code_identity()
    version = code["version"] or "unknown"
    if code["commit"] is None:
        return version
    changed = ", with changes" if code["dirty"] else ""
    return f"{version} (commit {code['commit'][:12]}{changed})"


def main(argv: Sequence[str] | None = None) -> int:
    """Parse arguments and run the chosen command."""
    args = build_parser().parse_args(argv)
    return args.handler(args)


def entry_point(argv: Sequence[str] | None = None) -> int:
    """Run the CLI with one-line errors and exit status 2 on bad input."""
    return run_guarded(main, argv)

"""Every command line's --help: each argument explained, each default shown, plain text."""

from __future__ import annotations

import argparse

import pytest

import ground_station.cli as gcs_cli
import mission.cli as mission_cli
import vehicle_sim.cli as vehicle_cli


def _parsers() -> list[tuple[str, argparse.ArgumentParser]]:
    top = mission_cli.build_parser()
    found = [("mission", top)]
    for action in top._actions:
        if isinstance(action, argparse._SubParsersAction):
            found += [(f"mission {name}", parser) for name, parser in action.choices.items()]
    found.append(("ground_station", gcs_cli.build_parser()))
    return [*found, ("vehicle_sim", vehicle_cli.build_parser())]


def _arguments(parser: argparse.ArgumentParser) -> list[argparse.Action]:
    skipped = (argparse._HelpAction, argparse._VersionAction, argparse._SubParsersAction)
    return [
        a for a in parser._actions if not isinstance(a, skipped) and a.help != argparse.SUPPRESS
    ]


@pytest.mark.parametrize(("name", "parser"), _parsers(), ids=[name for name, _ in _parsers()])
def test_every_argument_has_help_and_shows_its_default(name, parser):
    text = parser.format_help()
    assert "``" not in text and ":mod:" not in text, "plain text, no reStructuredText"
    for action in _arguments(parser):
        assert action.help, f"{name}: {action.dest} has no help"
        has_default = action.default is not None and action.default is not False
        if has_default:
            shown = parser._get_formatter()._expand_help(action)
            assert "default" in shown, (
                f"{name}: {action.dest}'s default {action.default!r} not shown"
            )


def test_a_default_of_zero_is_shown_and_an_unset_option_is_not():
    help_text = (
        mission_cli.build_parser()._subparsers._group_actions[0].choices["run"].format_help()
    )
    assert "(default: 0)" in help_text  # --seed
    assert "(default: None)" not in help_text and "(default: False)" not in help_text


def test_the_commands_are_console_scripts_as_sitl_tools_are():
    from importlib.metadata import entry_points

    import ground_station.__main__
    import mission.__main__
    import vehicle_sim.__main__

    # the scripts enter as python -m does: through __main__, which pins the numerics first
    scripts = {e.name: e for e in entry_points(group="console_scripts")}
    for name, function in [
        ("mission", mission.__main__.main),
        ("mission-vehicle", vehicle_sim.__main__.main),
        ("mission-ground-station", ground_station.__main__.main),
    ]:
        assert scripts[name].load() is function

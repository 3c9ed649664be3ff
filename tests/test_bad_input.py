"""Bad input everywhere: each case gives one line naming the file (or flag), the field or line
and the problem, exit status 2, and leaves no output behind (the cases: tests/bad_input/)."""

from __future__ import annotations

import pytest

import ground_station.cli as gcs_cli
import mission.cli as mission_cli
import vehicle_sim.cli as vehicle_cli
from tests.bad_input.command_cases import COMMAND_CASES
from tests.bad_input.file_cases import FILE_CASES

CASES = FILE_CASES + COMMAND_CASES


def _entry(case: str):
    if case.startswith(("gcs-", "wpl-gcs")):
        return gcs_cli.entry_point
    if case.startswith(("vehicle-", "key-vehicle")):
        return vehicle_cli.entry_point
    return mission_cli.entry_point


def test_the_table_covers_every_kind_of_input():
    assert len(CASES) >= 60
    kinds = {c[0].split("-")[0] for c in CASES}
    kinds_wanted = {"yaml", "wpl", "mesh", "run", "key", "gcs", "vehicle", "analyze", "plan"}
    assert kinds_wanted | {"study"} <= kinds


@pytest.mark.parametrize(("case", "argv", "expected"), CASES, ids=[c[0] for c in CASES])
def test_bad_input_gives_one_line_status_2_and_no_output(
    case, argv, expected, tmp_path, monkeypatch, capsys
):
    monkeypatch.chdir(tmp_path)  # default output directories would land here
    arguments = argv(tmp_path)
    (tmp_path / "out").mkdir()
    before = sorted(p.name for p in tmp_path.rglob("*"))
    try:
        status = _entry(case)(arguments)
    except SystemExit as exit_:  # argparse usage errors
        status = exit_.code
    err = capsys.readouterr().err
    assert status == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    for text in expected:
        assert text in lines[0], lines[0]
    assert "Traceback" not in err
    assert sorted(p.name for p in tmp_path.rglob("*")) == before, "no output left behind"

"""How far a run has got, on a terminal only: the cycle, simulated time and real-time factor
from the records as they grow, rewritten in place and cleared at the end."""

from __future__ import annotations

import io

from mission.runs import progress as progress_module
from mission.runs.progress import RunProgress


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def _record(t: float, k: int = 1) -> str:
    return f'{{"t": {t}, "k": {k}, "xhat": [0.0, 0.0, 7.0]}}\n'


def test_only_a_terminal_gets_the_line():
    assert RunProgress.wanted(Terminal()) and not RunProgress.wanted(io.StringIO())


def test_the_line_shows_the_latest_whole_record_and_is_cleared(tmp_path, monkeypatch):
    clock = iter([99.0, 100.0, 100.2, 102.0])
    monkeypatch.setattr(progress_module.time, "monotonic", lambda: next(clock))
    records, terminal = tmp_path / "records.jsonl", Terminal()
    progress = RunProgress(records, 900.0, terminal)
    progress.poll()  # no records yet (starting, compiling): nothing
    assert terminal.getvalue() == ""
    records.write_text(_record(0.5, 1))
    progress.poll()  # flying starts at 100 s of wall time
    assert terminal.getvalue() == "\rcycle 1, 0.5 of 900 s simulated"
    with records.open("a") as handle:
        handle.write(_record(1.0, 2) + _record(1.5, 3))
    progress.poll()  # 0.2 s later: not yet
    assert terminal.getvalue().count("\r") == 1
    with records.open("a") as handle:
        handle.write("".join(_record(0.5 * n, 2) for n in range(4, 401)))
        handle.write('{"t": 200.5, "k": 4')  # the last not whole
    progress.poll()
    assert terminal.getvalue().endswith("\rcycle 400, 200.0 of 900 s simulated, 100x real time")
    progress.clear()
    assert terminal.getvalue().endswith("\r" + " " * 51 + "\r") and not progress.shown

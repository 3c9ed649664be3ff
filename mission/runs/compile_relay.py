"""What the ground station says of its compilations during a run (a first run on a machine
compiles the support MPC): shown on ``mission run``'s stderr as it comes, counted so that a
run is not called stalled while something compiles, and summed for the run's summary."""

from __future__ import annotations

import sys
from pathlib import Path

from mission.codegen.news import DONE, FAILED, STARTED, compilations
from mission.procs.file_tail import FileTail


class CompileRelay:
    """Shows every whole compile line of a child's log (without the child's ``name: ``),
    reading only what is new, and counts the compilations begun and not yet done."""

    def __init__(self, log: Path) -> None:
        self.log = log
        self.open = 0
        self._file = FileTail(log)

    @property
    def compiling(self) -> bool:
        """Whether a compilation has begun and not finished."""
        return self.open > 0

    def poll(self) -> None:
        """Show what has come since the last poll."""
        for line in self._file.new_lines():
            text = line.decode("utf-8", "replace").split(": ", 1)[-1]
            if STARTED.match(text):
                self.open += 1
            elif DONE.match(text) or FAILED.match(text):
                self.open = max(0, self.open - 1)
            else:
                continue
            print(text, file=sys.stderr, flush=True)


def compile_summary(log: Path) -> dict[str, float]:
    """What a log says was compiled, and for how long (seconds, summed where said twice)."""
    try:
        text = log.read_text(encoding="utf-8", errors="replace")
    except OSError:
        return {}
    seconds: dict[str, float] = {}
    for what, s in compilations(text):
        seconds[what] = round(seconds.get(what, 0.0) + s, 1)
    return seconds

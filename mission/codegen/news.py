"""What a process says on stderr while it compiles numerical code, and reading it back: the
words are written here once, for the compiling process (:mod:`mission.codegen.casadi_cache`)
and for ``mission run``, which shows them and counts their time (this module imports no
casadi, so a command that only reads a log stays fast to start)."""

from __future__ import annotations

import re
import sys
from dataclasses import dataclass

STARTED = re.compile(r"^compiling (?P<what>.+?) with (?P<compiler>\S+): ")
DONE = re.compile(r"^compiled (?P<what>.+?) in (?P<s>\d+(?:\.\d+)?) s$")
FAILED = re.compile(r"^could not compile (?P<what>.+?) with \S+: ")


@dataclass(frozen=True)
class Compiling:
    """Who compiles what: ``who: compiling WHAT (PARTS) with gcc: ...`` on stderr, then
    ``who: compiled WHAT (PARTS) in S s``; ``prefix`` names its libraries in the cache."""

    who: str
    what: str
    prefix: str

    @property
    def starting(self) -> str:
        """How the line saying that compiling starts begins."""
        return f"compiling {self.what}"

    @property
    def done(self) -> str:
        """How the line saying that it is done begins."""
        return f"compiled {self.what}"

    def started(self, parts: list[str], compiler: str, cache: str) -> None:
        """Say that ``parts`` are being compiled with ``compiler`` into ``cache``."""
        self._say(
            f"{self.starting} ({', '.join(parts)}) with {compiler}: once per machine, "
            f"cached in {cache}"
        )

    def finished(self, parts: list[str], seconds: float) -> None:
        """Say that ``parts`` took ``seconds`` to compile."""
        self._say(f"{self.done} ({', '.join(parts)}) in {seconds:.1f} s")

    def failed(self, parts: list[str], compiler: str) -> None:
        """Say that ``parts`` could not be compiled (they are interpreted instead)."""
        self._say(
            f"could not compile {self.what} ({', '.join(parts)}) with {compiler}: "
            "interpreting it instead (the same results, slower)"
        )

    def _say(self, text: str) -> None:
        print(f"{self.who}: {text}", file=sys.stderr, flush=True)


def compilations(text: str) -> list[tuple[str, float]]:
    """Every compilation a log reports done: what, and its seconds, in order."""
    found = []
    for line in text.splitlines():
        done = DONE.match(line.split(": ", 1)[-1])
        if done:
            found.append((done["what"], float(done["s"])))
    return found

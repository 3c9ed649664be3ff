"""Start project processes for tests and always stop them, even when a test fails."""

from __future__ import annotations

import contextlib
import os
import re
import select
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
# ``mission run``'s documented status for a run flown to its end without completing
# (docs/robustness.md, "Exit statuses"); written out here, not imported, so that a change of it
# fails the tests that use it
EXIT_NOT_COMPLETED = 4
_LISTENING = re.compile(r"listening on ([\d.]+):(\d+)(?:, truth port (\d+))?")


@dataclass
class VehicleProcess:
    """A running ``python -m vehicle_sim`` and where it listens."""

    process: subprocess.Popen
    port: int
    truth_port: int | None
    banner: str

    @property
    def address(self) -> tuple[str, int]:
        """Its MAVLink address."""
        return ("127.0.0.1", self.port)

    def stop(self) -> str:
        """Terminate and return what it wrote to stderr after the banner."""
        return stop_process(self.process)


def mission(*arguments: str) -> subprocess.CompletedProcess:
    """``python -m mission ARGUMENTS`` from the repository's root, its output captured."""
    return subprocess.run(
        [sys.executable, "-m", "mission", *arguments],
        capture_output=True,
        text=True,
        timeout=600,
        cwd=ROOT,
    )


def vehicle_pids(parent: int, vehicle: str) -> list[int]:
    """The pids of ``parent``'s vehicle processes named ``vsim-VEHICLE`` (each vehicle names
    itself so, whether `mission run` forked it or started it as ``python -m vehicle_sim``)."""
    found = subprocess.run(
        ["pgrep", "-P", str(parent), "-x", f"vsim-{vehicle}"[:15]], capture_output=True, text=True
    )
    return [int(pid) for pid in found.stdout.split()]


def stop_process(process: subprocess.Popen, timeout_s: float = 10.0) -> str:
    """SIGTERM, then SIGKILL after ``timeout_s``; return the rest of stderr."""
    if process.poll() is None:
        process.send_signal(signal.SIGTERM)
    try:
        _, err = process.communicate(timeout=timeout_s)
    except subprocess.TimeoutExpired:
        process.kill()
        _, err = process.communicate()
    return err or ""


@contextlib.contextmanager
def vehicle_process(
    vehicle: str,
    *args: str,
    scenario: str = "along",
    home: tuple[float, float, float] | None = (0.0, -10.0, 7.0),
) -> Iterator[VehicleProcess]:
    """Run one vehicle on a free port for the duration of the ``with`` block."""
    command = [
        sys.executable,
        "-m",
        "vehicle_sim",
        "--scenario",
        scenario,
        "--vehicle",
        vehicle,
        "--port",
        "0",
        *(["--home", *map(str, home)] if home is not None else []),
        *args,
    ]
    process = subprocess.Popen(
        command,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        cwd=ROOT,
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
    )
    try:
        banner = _read_banner(process)
        match = _LISTENING.search(banner)
        assert match, banner
        truth = int(match.group(3)) if match.group(3) else None
        yield VehicleProcess(process, int(match.group(2)), truth, banner)
    finally:
        stop_process(process)


def _read_banner(process: subprocess.Popen, timeout_s: float = 60.0) -> str:
    deadline = time.monotonic() + timeout_s
    assert process.stderr is not None
    while time.monotonic() < deadline:
        ready, _, _ = select.select([process.stderr], [], [], 0.5)
        if ready:
            line = process.stderr.readline()
            if "listening on" in line:
                return line
            if not line and process.poll() is not None:
                break
    raise AssertionError(f"vehicle did not start (exit {process.poll()})")

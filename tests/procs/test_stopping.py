"""Stopping children: SIGTERM to all, SIGKILL to whoever ignores it after the grace period,
and every one waited for."""

from __future__ import annotations

import signal
import subprocess
import sys
import time

import pytest

from mission.procs.stopping import is_frozen, stop_processes

pytestmark = pytest.mark.slow  # starts processes

STUBBORN = (
    "import signal, time; signal.signal(signal.SIGTERM, signal.SIG_IGN); "
    "print(1, flush=True); time.sleep(60)"
)


def test_a_stubborn_child_is_killed_after_the_grace_and_a_polite_one_at_once():
    polite = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    stubborn = subprocess.Popen([sys.executable, "-c", STUBBORN], stdout=subprocess.PIPE)
    stubborn.stdout.readline()  # its handler is in place
    done = subprocess.Popen([sys.executable, "-c", "pass"])
    done.wait()
    start = time.monotonic()
    stop_processes([polite, stubborn, done], grace_s=1.0)
    took = time.monotonic() - start
    assert polite.returncode == -15 and stubborn.returncode == -9 and done.returncode == 0
    assert 0.9 < took < 10


def test_a_frozen_child_is_killed_at_once_not_after_the_grace():
    """A stopped process cannot act on SIGTERM: waiting the grace for it only delays the end
    (a run whose vehicle was frozen waited 10 s for it)."""
    frozen = subprocess.Popen(["sleep", "60"])
    frozen.send_signal(signal.SIGSTOP)
    deadline = time.monotonic() + 5
    while not is_frozen(frozen.pid):
        assert time.monotonic() < deadline, "the child never showed as stopped"
        time.sleep(0.01)
    start = time.monotonic()
    stop_processes([frozen], grace_s=10.0)
    assert frozen.returncode == -9 and time.monotonic() - start < 5
    assert not is_frozen(frozen.pid)  # gone: its stat file with it

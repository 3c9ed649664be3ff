"""SIGTERM or Ctrl-C ends every long command within 5 s and leaves none of its processes: a
run (vehicles, ground station and its helper), the benchmarks (their runs), a batch (its
runs), and a study of a study file."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from tests.processes import ROOT

pytestmark = pytest.mark.slow  # every test here starts runs
STOP_WITHIN_S = 5.0


def _group_alive(pgid: int) -> bool:
    try:
        os.killpg(pgid, 0)
    except ProcessLookupError:
        return False
    return True


def _ignore_sigint() -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _busy(out: Path) -> bool:
    """Some run of the command has flown its first cycles."""
    return any(len(p.read_bytes().splitlines()) >= 3 for p in out.rglob("records.jsonl"))


COMMANDS = {
    "run": ["run", "along", "--out", "{out}"],
    "bench": ["bench", "--only", "run"],
    "batch": ["batch", "along", "--trials", "1", "--jobs", "2", "--out", "{out}"],
    "study": ["study", "{study}", "--jobs", "2", "--out", "{out}"],
}


@pytest.mark.parametrize(
    ("command", "sent"),
    [
        ("run", signal.SIGTERM),
        ("bench", signal.SIGTERM),
        ("bench", signal.SIGINT),
        ("batch", signal.SIGINT),
        ("study", signal.SIGTERM),
    ],
    ids=["run-term", "bench-term", "bench-int", "batch-int", "study-term"],
)
def test_a_long_command_stops_within_5_s_and_leaves_no_process(tmp_path, command, sent):
    out = tmp_path / "out"
    study = tmp_path / "s.yaml"
    study.write_text("name: s\nscenarios: [along]\nmethods: [ac]\nseeds: [0, 1]\n")
    argv = [a.format(out=out, study=study) for a in COMMANDS[command]]
    env = {**os.environ, "TMPDIR": str(tmp_path)}  # the bench's runs go under tmp_path too
    process = subprocess.Popen(
        [sys.executable, "-m", "mission", *argv],
        cwd=ROOT,
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
        # Ctrl-C is tried on a command started as a shell starts a background job: with SIGINT
        # ignored, so that Python would not turn it into KeyboardInterrupt by itself
        preexec_fn=_ignore_sigint if sent == signal.SIGINT else None,
    )
    try:
        deadline = time.monotonic() + 120
        while not _busy(tmp_path):
            assert process.poll() is None and time.monotonic() < deadline, "it never got going"
            time.sleep(0.1)
        sent_at = time.monotonic()
        process.send_signal(sent)
        process.wait(timeout=30)
        while _group_alive(process.pid) and time.monotonic() - sent_at < 30:
            time.sleep(0.05)
        took = time.monotonic() - sent_at
        assert not _group_alive(process.pid), "processes were left behind"
        assert took <= STOP_WITHIN_S, f"{command} took {took:.1f} s to stop"
    finally:
        if _group_alive(process.pid):
            os.killpg(process.pid, signal.SIGKILL)
        process.wait()

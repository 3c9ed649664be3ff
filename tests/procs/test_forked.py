"""Forked children (mission.procs.forked) against real forks: what they keep, what they report,
how they end; and when forking is allowed."""

from __future__ import annotations

import ast
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from mission.procs.forked import start_forked

pytestmark = [  # every test here forks
    pytest.mark.slow,
    pytest.mark.skipif(not hasattr(os, "fork"), reason="POSIX fork only"),
]


def _report(argv: list[str]) -> int:
    """Print argv, the open descriptors, an environment variable; write to a kept pipe."""
    print("argv", argv)
    print("fds", sorted(int(n) for n in os.listdir("/proc/self/fd")))
    print("env", os.environ.get("FORKED_TEST_VALUE"))
    sys.stderr.write("to stderr\n")
    os.write(int(argv[0]), b"through the kept pipe")
    return 7


def test_a_forked_child_runs_the_function_with_only_its_kept_descriptors(tmp_path):
    log = tmp_path / "child.log"
    reader, writer = os.pipe()
    stray = os.open(os.devnull, os.O_RDONLY)  # open here, not kept: closed in the child
    try:
        child = start_forked(
            _report, [str(writer)], log, keep_fds=[writer], environment={"FORKED_TEST_VALUE": "x"}
        )
        assert child.wait(timeout=30) == 7 and child.returncode == 7
        assert os.read(reader, 100) == b"through the kept pipe"
    finally:
        for descriptor in (reader, writer, stray):
            os.close(descriptor)
    lines = log.read_text().splitlines()
    assert "to stderr" in lines
    assert f"argv ['{writer}']" in lines
    assert "env x" in lines
    fds = next(line for line in lines if line.startswith("fds "))
    # stdin, stdout, stderr, the kept pipe end, and the listing's own descriptor
    listed = ast.literal_eval(fds[4:])
    assert listed[:3] == [0, 1, 2] and writer in listed and stray not in listed
    assert len(listed) == 5
    assert "FORKED_TEST_VALUE" not in os.environ  # merged into the child's environment only


def _fail(argv: list[str]) -> int:
    raise RuntimeError(f"broken {argv[0]}")


def _exit_3(argv: list[str]) -> int:
    sys.exit(3)


def test_exceptions_and_exit_calls_become_exit_statuses(tmp_path):
    failed = start_forked(_fail, ["child"], tmp_path / "fail.log")
    exited = start_forked(_exit_3, [], tmp_path / "exit.log")
    assert failed.wait(timeout=30) == 1
    assert "RuntimeError: broken child" in (tmp_path / "fail.log").read_text()
    assert exited.wait(timeout=30) == 3


def _say(argv: list[str]) -> int:
    print(f"out {argv[0]}", flush=True)
    sys.stderr.write(f"err {argv[0]}\n")
    return 0


def test_without_a_log_the_child_writes_where_this_process_does(capfd):
    child = start_forked(_say, ["hello"], None)
    assert child.wait(timeout=30) == 0
    captured = capfd.readouterr()
    assert "out hello" in captured.out and "err hello" in captured.err


def _sleep(argv: list[str]) -> int:
    time.sleep(60)
    return 0


def test_a_forked_child_is_waited_for_terminated_and_killed_as_popen_would(tmp_path):
    child = start_forked(_sleep, [], tmp_path / "sleep.log")
    assert child.poll() is None
    with pytest.raises(subprocess.TimeoutExpired):
        child.wait(timeout=0.05)
    child.terminate()
    assert child.wait(timeout=30) == -signal.SIGTERM
    child.terminate()  # once waited for, it is not signalled again (its pid may be reused)

    stubborn = start_forked(_ignore_term_and_sleep, [], tmp_path / "stubborn.log")
    time.sleep(0.3)  # let it install its handler
    stubborn.terminate()
    with pytest.raises(subprocess.TimeoutExpired):
        stubborn.wait(timeout=0.3)
    stubborn.kill()
    assert stubborn.wait(timeout=30) == -signal.SIGKILL


def test_without_a_pidfd_the_wait_polls_to_the_same_effect(tmp_path, monkeypatch):
    def no_pidfd(pid: int, flags: int = 0) -> int:
        raise OSError("pidfd_open: not on this kernel")

    monkeypatch.setattr(os, "pidfd_open", no_pidfd, raising=False)
    child = start_forked(_sleep, [], tmp_path / "sleep.log")
    with pytest.raises(subprocess.TimeoutExpired):
        child.wait(timeout=0.05)
    child.kill()
    assert child.wait(timeout=30) == -signal.SIGKILL


def _ignore_term_and_sleep(argv: list[str]) -> int:
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    time.sleep(60)
    return 0


def test_a_process_with_a_second_thread_may_not_fork():
    script = (
        "import threading\n"
        "from mission.procs.forked import fork_is_safe\n"
        "print(fork_is_safe())\n"
        "stop = threading.Event()\n"
        "thread = threading.Thread(target=stop.wait)\n"
        "thread.start()\n"
        "print(fork_is_safe())\n"
        "stop.set(); thread.join()\n"
        "import time\n"  # the OS thread ends a moment after join() returns
        "deadline = time.monotonic() + 5\n"
        "while not fork_is_safe() and time.monotonic() < deadline: time.sleep(0.01)\n"
        "print(fork_is_safe())\n"
    )
    result = subprocess.run(
        [sys.executable, "-c", script],
        capture_output=True,
        text=True,
        timeout=60,
        env={**os.environ, "OPENBLAS_NUM_THREADS": "1"},
        cwd=Path(__file__).resolve().parents[2],
    )
    assert result.stdout.split() == ["True", "False", "True"], result.stderr

"""A stop request survives the loss of its KeyboardInterrupt, and handlers come back."""

from __future__ import annotations

import contextlib
import os
import signal

import pytest

from mission.procs.interrupts import StopRequest


def test_a_swallowed_interrupt_is_still_a_stop_request():
    with StopRequest() as stop:
        stop.check()  # nothing asked yet
        with contextlib.suppress(KeyboardInterrupt):  # as an at-fork hook or __del__ would
            os.kill(os.getpid(), signal.SIGTERM)
        with pytest.raises(KeyboardInterrupt):
            stop.check()


def test_the_previous_handlers_come_back():
    before = {n: signal.getsignal(n) for n in (signal.SIGINT, signal.SIGTERM)}
    with StopRequest():
        assert signal.getsignal(signal.SIGTERM) is not before[signal.SIGTERM]
    assert {n: signal.getsignal(n) for n in before} == before

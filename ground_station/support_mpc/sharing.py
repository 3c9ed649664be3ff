"""Who solves a cycle's support MPCs: this process alone, or this process and a helper.

A run is a chain that keeps one core busy at a time, and the support MPCs are most of the
ground station's cycle. With a helper process (:mod:`ground_station.support_mpc.helper`) the second
core takes part of them: the solves expected to take longest (by each support's last solve
time) are shared out longest first, each to whichever side has less to do, as in LPT
scheduling. A solve is a pure function of its request, so the plans are the same bit for bit
whichever process made them; only the timing differs.
"""

from __future__ import annotations

import contextlib
import os
import subprocess
import sys
from collections.abc import Callable, Sequence
from typing import BinaryIO

import numpy as np

from ground_station.support_mpc.helper import read_frame, write_frame
from ground_station.support_mpc.mpc import PlanRequest, SupportMpc, SupportPlan
from mission.config.settings import Scenario
from mission.procs.forked import ForkedProcess, fork_is_safe, start_forked
from mission.procs.process_life import child_environment

SET_UP_PIPE_BYTES = 1 << 20  # the set-up frame (a sigma_0 map of 40,000 voxels) is ~0.3 MB

Observable = Callable[[np.ndarray, np.ndarray], np.ndarray]


class HelperError(RuntimeError):
    """The helper process failed a solve (its traceback is the message)."""


class LocalPlanner:
    """Every support MPC solved here, one after another."""

    def __init__(self, mpc: SupportMpc, observable: Observable) -> None:
        self.mpc = mpc
        self.observable = observable

    def plan_all(self, requests: Sequence[PlanRequest]) -> dict[str, SupportPlan]:
        """The plans of these problems, by support name, in their order."""
        return {request.name: self.mpc.plan(request, self.observable) for request in requests}

    def close(self) -> None:
        """Nothing to release."""


class HelperPlanner(LocalPlanner):
    """Support MPCs shared between this process and one helper process.

    If the helper dies, its share is solved here from then on (same plans, a note on stderr).
    """

    def __init__(self, mpc: SupportMpc, observable: Observable, helper: MpcHelper) -> None:
        super().__init__(mpc, observable)
        self.helper: MpcHelper | None = helper
        self._expected_ms: dict[str, float] = {}

    def plan_all(self, requests: Sequence[PlanRequest]) -> dict[str, SupportPlan]:
        """The plans of these problems, by support name, in their order. The helper's share is
        sent first, so it solves while this process solves its own."""
        by_name = {request.name: request for request in requests}
        names = list(by_name)
        their_names, our_names = self._share(names)
        theirs = [by_name[name] for name in their_names]
        if theirs and not self._call(lambda h: h.send(theirs)):
            theirs, our_names = [], names
        plans = {name: self.mpc.plan(by_name[name], self.observable) for name in our_names}
        if theirs:
            answer = self._call(lambda h: h.receive())
            if answer is None:
                plans.update((r.name, self.mpc.plan(r, self.observable)) for r in theirs)
            elif isinstance(answer, str):
                raise HelperError(answer)
            else:
                plans.update((request.name, plan) for request, plan in zip(theirs, answer))
        for name, plan in plans.items():
            self._expected_ms[name] = plan.solve_ms
        return {name: plans[name] for name in names}

    def _share(self, names: Sequence[str]) -> tuple[list[str], list[str]]:
        """(the helper's supports, this process's): longest expected first, each to the side
        with less to do; nothing for the helper when it is gone or there is one support."""
        if self.helper is None or len(names) < 2:
            return [], list(names)
        expected = {name: self._expected_ms.get(name, 1.0) for name in names}
        theirs: list[str] = []
        ours: list[str] = []
        theirs_ms = ours_ms = 0.0
        for name in sorted(names, key=lambda n: -expected[n]):
            if not theirs or theirs_ms < ours_ms:  # ties stay here: no round trip
                theirs.append(name)
                theirs_ms += expected[name]
            else:
                ours.append(name)
                ours_ms += expected[name]
        return theirs, ours

    def _call(self, action):
        """``action(helper)``; None (and the helper dropped) if the helper is gone."""
        if self.helper is None:
            return None
        try:
            result = action(self.helper)
            return True if result is None else result
        except (EOFError, OSError):
            print("ground station: MPC helper stopped; solving its share here", file=sys.stderr)
            self.close()
            return None

    def close(self) -> None:
        """Stop the helper."""
        helper, self.helper = self.helper, None
        if helper is not None:
            helper.close()


class MpcHelper:
    """The helper process: started early (it builds its solver while the ground station
    connects), fed request lists, stopped by closing its input."""

    def __init__(self, label: str = "", fork: bool = True) -> None:
        """Start the helper: forked from this process where that is safe and ``fork`` allows
        it, else as ``python -m ground_station.support_mpc.helper --for LABEL`` (``label``, e.g. the
        run's directory, tells ``ps`` whose helper it is). Its set-up follows with
        :meth:`set_up`."""
        self.process: subprocess.Popen | ForkedProcess
        if fork and fork_is_safe():
            self.process, self._requests, self._answers = _forked_helper()
        else:
            self.process, self._requests, self._answers = _executed_helper(label)
        with contextlib.suppress(ImportError, OSError, AttributeError):  # else writes may wait
            import fcntl

            fcntl.fcntl(self._requests.fileno(), fcntl.F_SETPIPE_SZ, SET_UP_PIPE_BYTES)

    def set_up(self, scenario: Scenario, sigma0_m: np.ndarray) -> None:
        """Send the scenario and the sigma_0 map, so the helper builds the same solver as
        this process without computing the map again. The pipe is widened to hold them, so
        this returns at once while the helper is still importing."""
        self.send((scenario, np.asarray(sigma0_m, dtype=float)))

    def send(self, value) -> None:
        """One frame to the helper (BrokenPipeError if it is gone)."""
        write_frame(self._requests, value)

    def receive(self):
        """The helper's next answer (EOFError if it is gone)."""
        return read_frame(self._answers)

    def close(self) -> None:
        """Close its input, so it ends, and wait for it."""
        for stream in (self._requests, self._answers):
            with contextlib.suppress(OSError):
                stream.close()
        try:
            self.process.wait(timeout=5)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()


def _forked_helper() -> tuple[ForkedProcess, BinaryIO, BinaryIO]:
    """A helper forked from this process: (process, its requests' writer, answers' reader)."""
    from ground_station.support_mpc.helper import serve_descriptors

    requests_in, requests_out = os.pipe()
    answers_in, answers_out = os.pipe()
    child_ends = [requests_in, answers_out]
    try:
        process = start_forked(
            serve_descriptors, [str(d) for d in child_ends], None, child_ends, child_environment()
        )
    finally:
        for descriptor in child_ends:
            os.close(descriptor)
    return process, open(requests_out, "wb"), open(answers_in, "rb")


def _executed_helper(label: str) -> tuple[subprocess.Popen, BinaryIO, BinaryIO]:
    """``python -m ground_station.support_mpc.helper``: (process, its stdin, its stdout)."""
    process = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "ground_station.support_mpc.helper",
            *(["--for", label] if label else []),
        ],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        env=child_environment(),
    )
    assert process.stdin is not None and process.stdout is not None
    return process, process.stdin, process.stdout

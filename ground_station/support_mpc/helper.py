"""``python -m ground_station.support_mpc.helper``: a process that solves support MPCs for the
ground station, so two cores share a cycle's solves.

It reads pickled frames on stdin and answers on stdout: first the scenario and the ground
station's sigma_0 map (it builds its own world and solver, the same as the ground
station's), then lists of
:class:`~ground_station.support_mpc.mpc.PlanRequest`, each answered with the list of plans or an
error text. A frame is a 4-byte big-endian length and a pickle; both ends are this program.
The helper ends at end of input, i.e. when the ground station closes the pipe or dies.

A ground station with one thread forks its helper (:mod:`mission.procs.forked`), which then serves
two pipes (:func:`serve_descriptors`) with the station's imports already made; otherwise it
starts ``python -m ground_station.support_mpc.helper``, whose ``--for LABEL`` (the station's output
directory) only names it in ``ps``. Either way it calls itself ``gcs-mpc-helper``.
"""

from __future__ import annotations

import contextlib
import pickle
import signal
import struct
import sys
import traceback
from typing import Any, BinaryIO

HEADER = struct.Struct(">I")


def write_frame(stream: BinaryIO, value: Any) -> None:
    """One length-prefixed pickle, flushed."""
    data = pickle.dumps(value, protocol=pickle.HIGHEST_PROTOCOL)
    stream.write(HEADER.pack(len(data)) + data)
    stream.flush()


def read_frame(stream: BinaryIO) -> Any:
    """The next frame's value; EOFError at a clean or broken end of the stream."""
    header = stream.read(HEADER.size)
    if len(header) < HEADER.size:
        raise EOFError
    (size,) = HEADER.unpack(header)
    data = stream.read(size)
    if len(data) < size:
        raise EOFError
    return pickle.loads(data)


def serve(requests: BinaryIO, answers: BinaryIO) -> None:
    """Build the solver from the first frame, then answer request lists until end of input."""
    from ground_station.support_mpc.mpc import SupportMpc
    from mission.procs.process_life import freeze_startup_heap
    from mission.world.model import KnownWorld

    try:
        scenario, sigma0 = read_frame(requests)
    except EOFError:
        return
    world = KnownWorld(scenario)
    mpc = SupportMpc(
        scenario.control, world.map_grid(), world.camera, sigma0, others=scenario.task.supports
    )
    freeze_startup_heap()
    while True:
        try:
            batch = read_frame(requests)
        except EOFError:
            return
        try:
            answer: Any = [mpc.plan(request, world.camera.observable) for request in batch]
        except Exception:  # reported to the ground station, which stops the run with it
            answer = traceback.format_exc(limit=3)
        write_frame(answers, answer)


PROCESS_NAME = "gcs-mpc-helper"


def main() -> int:
    """Serve on stdin/stdout; Ctrl-C is the ground station's to handle (it closes the pipe)."""
    return _serve_quietly(sys.stdin.buffer, sys.stdout.buffer)


def serve_descriptors(argv: list[str]) -> int:
    """Serve the pipe ends whose descriptors are ``argv``: requests in, answers out (the
    forked helper's entry point)."""
    requests, answers = (int(descriptor) for descriptor in argv)
    with open(requests, "rb") as incoming, open(answers, "wb") as outgoing:
        return _serve_quietly(incoming, outgoing)


def _serve_quietly(requests: BinaryIO, answers: BinaryIO) -> int:
    from mission.procs.process_life import name_this_process

    name_this_process(PROCESS_NAME)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    with contextlib.suppress(BrokenPipeError):  # the ground station went away
        serve(requests, answers)
    return 0


if __name__ == "__main__":
    from mission.procs.numerics import prepare_numerics

    prepare_numerics()  # before serve() imports numpy
    sys.exit(main())

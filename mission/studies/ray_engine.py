"""The Ray engine: each run is one Ray task on whichever node has a free core.

``--address`` (or ``RAY_ADDRESS``) joins a running cluster; without one a Ray instance is
started on this machine for the study and stopped after it. A task prepares the run in a
temporary folder on its node, runs it, and returns its summary and its folder (packed), so
the nodes share no filesystem with the driver. Cancelling the study (Ctrl-C) cancels every
task; the killed worker's ``mission run`` dies with it (``--exit-with-parent``), and its
vehicles and ground station with that.
"""

from __future__ import annotations

import contextlib
import os
import re
import shutil
import socket
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from mission.config.errors import InputError
from mission.studies.execute import Keep, conclude, pack, prepare, start, this_node, unpack
from mission.studies.local_engine import Done
from mission.studies.runkeys import StudyRun

MIN_RAY = (2, 59)  # token authentication on by default for a local instance
INSTALL_HINT = "the Ray engine needs Ray 2.59 or later: pip install -e '.[ray]'"
CORES_PER_RUN = 1  # the ground station's core; the vehicles sleep most of a step
WAIT_S = 0.5
FAILURE_FILE = "failure.txt"  # why a task failed, where its folder would have been
REACH_S = 10.0  # how long a cluster's head may take to accept a connection


def check_reachable(address: str | None, flag: str = "--address") -> None:
    """A cluster address (``--address``, else ``RAY_ADDRESS``) whose head answers on its port
    within REACH_S; Ray itself retries an unreachable head for minutes. ``auto`` and Ray
    Client addresses (``ray://``) are left to Ray."""
    address = address or os.environ.get("RAY_ADDRESS")
    if not address or address == "auto" or address.startswith("ray://"):
        return
    where = "command line" if flag == "--address" else "environment"
    host, _, port = address.rpartition(":")
    if not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise InputError(where, flag, f"{address!r} is not HOST:PORT")
    try:
        socket.create_connection((host.strip("[]"), int(port)), timeout=REACH_S).close()
    except OSError as error:
        raise InputError(
            where, flag, f"no Ray head answers at {address} ({error.strerror or error})"
        ) from None


def require_ray() -> Any:
    """The ``ray`` module, or one line on how to install it."""
    try:
        import ray
    except ImportError:
        raise InputError("command line", "--engine ray", INSTALL_HINT) from None
    version = tuple(int(part) for part in re.findall(r"\d+", ray.__version__)[:2])
    if version < MIN_RAY:  # before 2.59 a local Ray listened on every interface, unauthenticated
        raise InputError("command line", "--engine ray", f"Ray {ray.__version__}: {INSTALL_HINT}")
    return ray


@dataclass(frozen=True)
class RayEngine:
    """Runs as Ray tasks: on a cluster at ``address``, else on a Ray started here with
    ``jobs`` CPUs; at most ``jobs`` in flight when given."""

    address: str | None
    jobs: int | None

    @property
    def cores(self) -> int | None:
        """How many runs go at once: ``jobs``; this machine's cores for a Ray started here;
        None (as many as it has cores) on a cluster."""
        if self.jobs:
            return self.jobs
        return None if self.address or os.environ.get("RAY_ADDRESS") else os.cpu_count()

    @property
    def description(self) -> str:
        """What the progress line says of the engine."""
        where = f"cluster at {self.address}" if self.address else "a local Ray"
        return f"Ray engine on {where}"

    def run(self, runs: list[StudyRun], runs_dir: Path, keep: Keep, done: Done) -> None:
        """Run every one of ``runs`` as a task; on any exit cancel those not finished."""
        ray = require_ray()
        os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")  # no usage reports
        started_here = not ray.is_initialized()
        with contextlib.ExitStack() as cleanup:
            if started_here:
                _start_ray(ray, self.address, self.jobs)
                cleanup.callback(ray.shutdown)
                if not (self.address or os.environ.get("RAY_ADDRESS")):
                    keep_token_private()
            self._run_tasks(ray, runs, runs_dir, keep, done)

    def _run_tasks(
        self, ray: Any, runs: list[StudyRun], runs_dir: Path, keep: Keep, done: Done
    ) -> None:
        """Submit the runs, at most ``jobs`` in flight, and collect them as they finish."""
        task = ray.remote(num_cpus=CORES_PER_RUN, max_retries=0)(run_on_node)
        queue = list(runs)
        in_flight: dict[Any, StudyRun] = {}
        limit = self.jobs or len(runs)
        try:
            while queue or in_flight:
                while queue and len(in_flight) < limit:
                    run = queue.pop(0)
                    in_flight[task.remote(run, keep)] = run
                ready, _ = ray.wait(list(in_flight), num_returns=1, timeout=WAIT_S)
                for ref in ready:
                    run = in_flight.pop(ref)
                    _collect(ray, ref, run, runs_dir, done)
        finally:
            for ref in in_flight:
                ray.cancel(ref, force=True)


def _start_ray(ray: Any, address: str | None, jobs: int | None) -> None:
    address = address or os.environ.get("RAY_ADDRESS")
    quiet = {"log_to_driver": False, "configure_logging": True, "logging_level": "ERROR"}
    if address:  # the cluster's own authentication (RAY_AUTH_MODE=token, docs/studies.md)
        ray.init(address=address, **quiet)
    else:
        ray.init(num_cpus=jobs or os.cpu_count() or 1, include_dashboard=False, **quiet)


def keep_token_private(home: Path | None = None) -> None:
    """A local Ray (2.59+) authenticates every call with the token in ~/.ray/auth_token,
    which it writes readable by every local user: make it the owner's alone."""
    token = (home or Path.home()) / ".ray" / "auth_token"
    with contextlib.suppress(OSError):  # none, or not ours: Ray's own doing
        if token.is_file() and token.stat().st_mode & 0o077:
            token.chmod(0o600)


def _collect(ray: Any, ref: Any, run: StudyRun, runs_dir: Path, done: Done) -> None:
    """Unpack a finished task's folder under ``runs_dir`` and report it."""
    try:
        summary, data, wall = ray.get(ref)
    except Exception as error:  # the task's worker died (or the task raised): the run failed
        folder = runs_dir / run.folder  # where the progress line says to look
        folder.mkdir(parents=True, exist_ok=True)
        (folder / FAILURE_FILE).write_text(f"{type(error).__name__}: {error}\n")
        done(run, None, 0.0)
        return
    unpack(data, runs_dir / run.folder)
    done(run, summary, wall)


def run_on_node(run: StudyRun, keep: Keep) -> tuple[dict | None, bytes, float]:
    """A Ray task: the run in a temporary folder on this node; (summary or None, the folder
    packed, wall seconds)."""
    import ray

    node = f"{this_node()}/{ray.get_runtime_context().get_node_id()[:8]}"
    scratch = Path(tempfile.mkdtemp(prefix="mission-study-"))
    try:
        run_dir = scratch / run.folder
        prepare(run, run_dir)
        started = time.monotonic()
        status = start(run, run_dir, mpc_helper=False, keep=keep).wait()
        wall = time.monotonic() - started
        summary = conclude(run, run_dir, status, node, keep)
        return summary, pack(run_dir), wall
    finally:
        shutil.rmtree(scratch, ignore_errors=True)

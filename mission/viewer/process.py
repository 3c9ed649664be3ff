"""The Rerun viewer as a child process: the web viewer (an HTTP server for the viewer's page and a
gRPC server the recording streams to) or the native viewer, from the ``rerun`` executable that
the rerun-sdk package ships.

Everything binds to 127.0.0.1 (``--bind``; Rerun's default is every interface), and Rerun's
usage analytics are off: the child gets its own configuration folder (``XDG_CONFIG_HOME``,
``XDG_DATA_HOME``) under the project's cache, whose ``rerun/analytics.json`` says so. The
child dies with this process (Linux's parent-death signal) and :func:`stop_viewer` stops it.
"""

from __future__ import annotations

import importlib.util
import json
import os
import re
import shutil
import subprocess
import tempfile
import time
import uuid
from dataclasses import dataclass
from pathlib import Path
from typing import Literal
from urllib.parse import quote

from mission.procs.process_life import die_with_parent
from mission.procs.stopping import stop_processes

LOOPBACK = "127.0.0.1"
START_TIMEOUT_S = 30.0
VIEWER_NICENESS = 10
_GRPC = re.compile(r"Listening for gRPC connections on ([\d.]+):(\d+)")
_WEB = re.compile(r"Hosting a web-viewer at (http://[\d.]+:\d+)")


class ViewerFailed(RuntimeError):
    """The viewer could not start; says why."""


@dataclass
class ViewerProcess:
    """A started viewer: where a recording streams to, and (web) where a browser opens it."""

    process: subprocess.Popen
    grpc_url: str  # rerun+http://127.0.0.1:PORT/proxy
    web_url: str | None  # the page that opens the stream, for --web
    log: Path
    temporary_log: bool = False  # removed when the viewer stops


def rerun_executable() -> Path:
    """The ``rerun`` binary of the installed rerun-sdk (package ``rerun_cli``)."""
    spec = importlib.util.find_spec("rerun_cli")
    if spec is None or not spec.submodule_search_locations:
        raise ViewerFailed("rerun-sdk is not installed (python -m pip install -e .)")
    path = Path(next(iter(spec.submodule_search_locations))) / "rerun"
    if not path.is_file():
        raise ViewerFailed(f"rerun-sdk has no viewer executable at {path}")
    return path


def viewer_environment() -> dict[str, str]:
    """The environment of a viewer child: the project's own Rerun configuration, analytics off."""
    base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    home = base / "bridge-uav-formation" / "rerun"
    try:
        _write_analytics_off(home)
    except OSError:
        home = Path(tempfile.mkdtemp(prefix="bridge-uav-rerun-"))
        _write_analytics_off(home)
    return {
        **os.environ,
        "XDG_CONFIG_HOME": str(home / "config"),
        "XDG_DATA_HOME": str(home / "data"),
    }


def _write_analytics_off(home: Path) -> None:
    config = home / "config" / "rerun" / "analytics.json"
    config.parent.mkdir(parents=True, exist_ok=True)
    try:
        settings = json.loads(config.read_text())
    except (OSError, ValueError):
        settings = {}
    if settings.get("analytics_enabled") is False:
        return
    settings = {
        "analytics_enabled": False,
        "analytics_id": settings.get("analytics_id") or uuid.uuid4().hex,
        "metadata": {},
        "config_file_path": str(config),
        "data_dir_path": str(home / "data" / "rerun" / "analytics"),
    }
    config.write_text(json.dumps(settings) + "\n")


def start_viewer(kind: Literal["web", "native"], log: Path | None = None) -> ViewerProcess:
    """Start a viewer and wait until it listens; its output goes to ``log`` (a temporary file
    removed when it stops, if None)."""
    arguments = ["--bind", LOOPBACK, "--port", "0"]
    if kind == "web":
        arguments += ["--serve-web", "--web-viewer-port", "0"]
    temporary = log is None
    if log is None:
        log = Path(tempfile.mkdtemp(prefix="bridge-uav-viewer-")) / "viewer.log"
    log.parent.mkdir(parents=True, exist_ok=True)
    with log.open("w") as handle:
        process = subprocess.Popen(
            [str(rerun_executable()), *arguments],
            stdin=subprocess.DEVNULL,
            stdout=handle,
            stderr=subprocess.STDOUT,
            env=viewer_environment(),
            preexec_fn=_as_viewer_child,
        )
    viewer = ViewerProcess(process, "", None, log, temporary)
    try:
        _await_listening(viewer, kind == "web")
    except BaseException:
        stop_viewer(viewer)
        raise
    return viewer


def _as_viewer_child() -> None:
    """In the viewer's process before it starts: die with this one; yield the CPU to the
    mission's processes (the live view must not slow them)."""
    die_with_parent()
    os.nice(VIEWER_NICENESS)


def _await_listening(viewer: ViewerProcess, web: bool) -> None:
    deadline = time.monotonic() + START_TIMEOUT_S
    while time.monotonic() < deadline:
        text = viewer.log.read_text(errors="replace")
        grpc, page = _GRPC.search(text), _WEB.search(text)
        if grpc and (page or not web):
            viewer.grpc_url = f"rerun+http://{grpc.group(1)}:{grpc.group(2)}/proxy"
            if page:
                viewer.web_url = f"{page.group(1)}/?url={quote(viewer.grpc_url, safe='')}"
            return
        if viewer.process.poll() is not None:
            last = text.strip().splitlines()[-1:] or ["no output"]
            raise ViewerFailed(f"the viewer exited at start: {last[0][:200]}")
        time.sleep(0.05)
    raise ViewerFailed(f"the viewer did not start within {START_TIMEOUT_S:g} s (see {viewer.log})")


def stop_viewer(viewer: ViewerProcess) -> None:
    """Stop the viewer (SIGTERM, then SIGKILL after 5 s)."""
    stop_processes([viewer.process], grace_s=5.0)
    if viewer.temporary_log:
        shutil.rmtree(viewer.log.parent, ignore_errors=True)

"""``mission view RUN_DIR``: a finished run replayed from its own files into a viewer (native,
or the web viewer on 127.0.0.1) and/or a recording file."""

from __future__ import annotations

import os
import sys
from pathlib import Path
from typing import Literal

from mission.config.settings import Scenario
from mission.procs.disk_full import fresh, removed_if_disk_fills
from mission.procs.interrupts import StopRequest
from mission.viewer.feed import RunFeed
from mission.viewer.process import ViewerProcess, start_viewer, stop_viewer

ViewerKind = Literal["web", "native"]


def viewer_kind(web: bool) -> ViewerKind:
    """``web`` if asked for or if there is no display for a native window."""
    if web or not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        return "web"
    return "native"


def replay_run(
    run_dir: Path, scenario: Scenario, viewer: ViewerKind | None, save: Path | None
) -> int:
    """Send the whole run to a viewer (then wait until it is closed or Ctrl-C) and/or ``save``."""
    feed = RunFeed(run_dir, scenario)
    process = start_viewer(viewer) if viewer else None
    try:
        from mission.viewer.recording import Recording

        with removed_if_disk_fills(*fresh(*([save] if save is not None else []))):
            rec = Recording(run_dir.name, feed.scene, process and process.grpc_url, save)
            try:
                rec.send(feed.read(final=True))
            finally:
                rec.close()
        if save is not None:
            print(f"wrote {save} (open it with: rerun {save})", flush=True)
        if process is not None:
            wait_for_viewer(process)
    finally:
        if process is not None:
            stop_viewer(process)
    return 0


def wait_for_viewer(process: ViewerProcess) -> None:
    """Say where the viewer is, then wait until its window is closed, Ctrl-C or SIGTERM."""
    where = process.web_url or "the native viewer's window"
    print(f"viewer at {where} (Ctrl-C to stop)", flush=True)
    # Ctrl-C and SIGTERM end the wait, even where SIGINT was ignored (a background job)
    try:
        with StopRequest():
            process.process.wait()
    except KeyboardInterrupt:
        print("viewer stopped", file=sys.stderr)

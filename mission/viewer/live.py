"""``mission run --view``: the run streamed to a viewer while it flies.

The orchestrator calls :meth:`LiveView.poll` from its supervision loop; each call reads what
the ground station has added to its files since the last (the same reading as the replay, so
the live view and ``mission view`` show the same rows) and streams it. Rerun is imported, and
its recording (with its threads) made, only at the first poll: by then every vehicle has been
forked, which a process with threads may not do. The viewer and this process then run at a
lower priority than the mission's processes.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path
from typing import Any

from mission.config.settings import Scenario
from mission.viewer.feed import RunFeed
from mission.viewer.process import ViewerProcess, stop_viewer

POLL_EVERY_S = 0.5  # wall seconds between two reads of the run's files
NICENESS = 10  # the view yields the CPU to the vehicles and the ground station


class LiveView:
    """Streams a running mission's folder to a viewer and/or a recording file."""

    def __init__(
        self,
        out_dir: Path,
        scenario: Scenario,
        viewer: ViewerProcess | None,
        save: Path | None = None,
    ) -> None:
        self.out_dir = out_dir
        self.scenario = scenario
        self.viewer = viewer
        self.save = save
        self._feed: RunFeed | None = None
        self._rec: Any = None
        self._last = float("-inf")
        self._failed = False

    def poll(self, final: bool = False) -> None:
        """Stream what is new (at most every POLL_EVERY_S, unless ``final``). A view that
        fails says so once on stderr and stops; the run goes on (its files are its record)."""
        now = time.monotonic()
        if self._failed or (not final and now - self._last < POLL_EVERY_S):
            return
        self._last = now
        try:
            self._stream(final)
        except Exception as error:  # the view must never end the mission
            self._failed = True
            print(f"live view stopped: {error}", file=sys.stderr, flush=True)

    def _stream(self, final: bool) -> None:
        if self._feed is None:
            os.nice(NICENESS)  # every child is started by now: this process alone
            self._feed = RunFeed(self.out_dir, self.scenario)
        if self._rec is None:
            from mission.viewer.recording import Recording

            url = self.viewer.grpc_url if self.viewer else None
            self._rec = Recording(self.out_dir.name, self._feed.scene, url, self.save)
        frame = self._feed.read(final)
        if frame:
            self._rec.send(frame)

    def finish(self) -> None:
        """The run is over: stream the rest and complete the recording."""
        self.poll(final=True)
        self._close_recording()

    def close(self) -> None:
        """Complete the recording if the run did not (interrupted), then stop the viewer
        (after :func:`~mission.viewer.replay.wait_for_viewer`, if wanted)."""
        self._close_recording()
        if self.viewer is not None:
            stop_viewer(self.viewer)

    def _close_recording(self) -> None:
        if self._rec is not None:
            rec, self._rec = self._rec, None
            try:
                rec.close()
            except Exception as error:  # as in poll: never at the run's expense
                print(f"live view stopped: {error}", file=sys.stderr, flush=True)

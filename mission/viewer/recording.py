"""A Rerun recording of a run, streamed to a viewer, saved to a file, or both."""

from __future__ import annotations

from pathlib import Path

import rerun as rr

from mission.viewer.layout import blueprint
from mission.viewer.scene import Scene
from mission.viewer.send import send_scene

APPLICATION_ID = "bridge-uav-formation"


def open_recording(
    name: str, scene: Scene, grpc_url: str | None, save: Path | None
) -> rr.RecordingStream:
    """A recording named after the run, with the layout and the scene already sent."""
    rec = rr.RecordingStream(APPLICATION_ID, recording_id=name)
    sinks: list = []
    if grpc_url is not None:
        sinks.append(rr.GrpcSink(grpc_url))
    if save is not None:
        sinks.append(rr.FileSink(str(save)))
    rec.set_sinks(*sinks, default_blueprint=blueprint(scene))
    rec.send_recording_name(name)
    send_scene(rec, scene)
    return rec


def close_recording(rec: rr.RecordingStream) -> None:
    """Everything sent and the file (if any) complete."""
    rec.flush()
    rec.disconnect()

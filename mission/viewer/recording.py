"""A Rerun recording of a run, streamed to a viewer, saved to a file, or both.

The file is written here, from a Rerun binary stream, not by Rerun's file sink: on a full disk
that sink could leave ``set_sinks`` waiting for ever, where our own write raises ENOSPC, which
the command turns into one line and exit status 3 (mission/procs/disk_full.py)."""

from __future__ import annotations

from pathlib import Path
from typing import BinaryIO

import rerun as rr

from mission.viewer.frame import Frame
from mission.viewer.layout import blueprint
from mission.viewer.scene import Scene
from mission.viewer.send import send_frame, send_scene

APPLICATION_ID = "bridge-uav-formation"


class Recording:
    """The run's recording: to a viewer at ``grpc_url`` and/or into the file ``save``."""

    def __init__(self, name: str, scene: Scene, grpc_url: str | None, save: Path | None) -> None:
        self._scene = scene
        self._save = save
        self._streams: list[rr.RecordingStream] = []
        self._binary: rr.BinaryStream | None = None
        self._file: BinaryIO | None = None
        if grpc_url is not None:
            viewer = rr.RecordingStream(APPLICATION_ID, recording_id=name)
            viewer.set_sinks(rr.GrpcSink(grpc_url), default_blueprint=blueprint(scene))
            self._streams.append(viewer)
        if save is not None:
            saved = rr.RecordingStream(APPLICATION_ID, recording_id=name)
            self._binary = saved.binary_stream()
            saved.send_blueprint(blueprint(scene))
            self._file = Path(save).open("wb")  # noqa: SIM115 (closed by close())
            self._streams.append(saved)
        try:
            for rec in self._streams:
                rec.send_recording_name(name)
                send_scene(rec, scene)
        except BaseException:
            self.close()
            raise

    def send(self, frame: Frame) -> None:
        """The frame to the viewer and the file."""
        for rec in self._streams:
            send_frame(rec, frame, self._scene)

    def close(self) -> None:
        """Everything sent and the file (if any) written whole and closed."""
        file, self._file = self._file, None
        try:
            for rec in self._streams:
                rec.flush()
            if file is not None and self._binary is not None:
                self._write(file, self._binary.read(flush=True) or b"")
        finally:
            if file is not None:
                file.close()
            for rec in self._streams:
                rec.disconnect()

    def _write(self, file: BinaryIO, data: bytes) -> None:
        # read once: an RRD read in parts does not read back (each part's checksum is its own)
        try:
            file.write(data)
            file.flush()  # a full disk raises here, not at the close that follows
        except OSError as error:
            if error.filename is None:  # name the file, as the command's one line must
                raise OSError(error.errno, error.strerror, str(self._save)) from error
            raise

"""Write output files so that a failure never leaves a half-written file behind, with the
permissions any other file the user creates would get (the umask honoured)."""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Callable
from pathlib import Path

from mission.procs.disk_full import NO_SPACE_ERRNOS


def write_atomically(path: Path, write: Callable[[str], None]) -> None:
    """Call ``write(temp_path)`` then move the result over ``path`` in one rename."""
    path = Path(path)
    try:
        handle, temp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".part")
    except OSError as error:  # a read-only or full file system: name the file meant
        if error.errno in NO_SPACE_ERRNOS:
            raise OSError(error.errno, os.strerror(error.errno), str(path)) from error
        raise
    os.close(handle)
    try:
        write(temp)
        os.chmod(temp, 0o666 & ~current_umask())  # mkstemp makes it 0600
        os.replace(temp, path)
    except OSError as error:
        Path(temp).unlink(missing_ok=True)
        if error.errno in NO_SPACE_ERRNOS and error.filename is None:  # name the file meant
            raise OSError(error.errno, os.strerror(error.errno), str(path)) from error
        raise
    except BaseException:
        Path(temp).unlink(missing_ok=True)
        raise


def write_text_atomically(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` atomically (UTF-8)."""
    write_atomically(path, lambda temp: Path(temp).write_text(text, encoding="utf-8"))


def current_umask() -> int:
    """This process's umask, read without changing it where Linux tells it (/proc), else by
    setting and restoring it."""
    with contextlib.suppress(OSError, ValueError):
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("Umask:"):
                return int(line.split()[1], 8)
    mask = os.umask(0o022)
    os.umask(mask)
    return mask

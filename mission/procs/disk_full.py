"""A full disk (or an exhausted quota, a read-only file system, a file over the size limit):
said on one line naming the file, exit status :data:`EXIT_NO_SPACE`, and what the command had
begun to write removed, so no half output is left for a later command to mistake for a whole one."""

from __future__ import annotations

import contextlib
import errno
import os
import shutil
from collections.abc import Iterator
from pathlib import Path

# and what fails a write alike: a read-only file system, a file over the size limit (ulimit -f)
NO_SPACE_ERRNOS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EROFS, errno.EFBIG})
EXIT_NO_SPACE = 3


def no_space_error(error: BaseException | None) -> OSError | None:
    """The OSError of a full disk in ``error`` or the exceptions it was raised from or
    during (None: not a full disk)."""
    seen: set[int] = set()
    while error is not None and id(error) not in seen:
        seen.add(id(error))
        if isinstance(error, OSError) and error.errno in NO_SPACE_ERRNOS:
            return error
        error = error.__cause__ or error.__context__
    return None


def no_space_line(error: OSError, fallback: str = "an output file") -> str:
    """The one line that says so."""
    said = os.strerror(error.errno).lower() if error.errno else "no space left on device"
    return f"error: {error.filename or fallback}: {said}"


@contextlib.contextmanager
def removed_if_disk_fills(*paths: Path) -> Iterator[None]:
    """Run the block; if it fails for a full disk, remove ``paths`` (files or folders this
    command creates: pass only those that did not exist before it) and raise again."""
    try:
        yield
    except BaseException as error:
        if no_space_error(error) is not None:
            for path in paths:
                if path.is_dir() and not path.is_symlink():
                    shutil.rmtree(path, ignore_errors=True)
                else:
                    path.unlink(missing_ok=True)
        raise


def fresh(*paths: Path) -> list[Path]:
    """Those of ``paths`` that do not exist yet (what a command may remove again)."""
    return [path for path in paths if not path.exists()]

"""Output locations checked before anything is started or written: a directory a run may
create, or a file it may write, named by a flag. Permission bits do not say everything (root
may "write" under /proc, where nothing can be made; a read-only mount): the directory that
will hold the output is probed by making and removing an empty scratch folder in it, and
nothing else is created."""

from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path

from mission.config.errors import InputError


def check_output_dir(path: Path, flag: str) -> None:
    """``path`` can be a directory this process makes (or fills): it is not a file, it lies
    under no file, and its nearest existing ancestor is a directory we may write in."""
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise InputError("command line", flag, f"{str(path)!r} is a file, not a directory")
    _check_writable_ancestor(path, flag)


def check_output_file(path: Path, flag: str, suffixes: tuple[str, ...] = ()) -> None:
    """``path`` can be a file this process writes: the right suffix, not a directory, in an
    existing directory we may write in."""
    path = Path(path)
    if suffixes and path.suffix.lower() not in suffixes:
        wanted = " or ".join(suffixes)
        raise InputError("command line", flag, f"{str(path)!r}: the file name must end in {wanted}")
    if path.is_dir():
        raise InputError("command line", flag, f"{str(path)!r} is a directory, not a file")
    if path.is_symlink() and not path.exists():
        raise InputError("command line", flag, f"{str(path)!r} is a link to a missing file")
    parent = path.parent
    if not parent.is_dir():
        raise InputError("command line", flag, f"{str(path)!r}: no directory {str(parent)!r}")
    if not os.access(parent, os.W_OK | os.X_OK) or not _can_make_in(parent):
        raise InputError("command line", flag, f"{str(path)!r}: cannot write in {str(parent)!r}")


def _can_make_in(directory: Path) -> bool:
    """Whether a folder can really be made (and removed) in ``directory``."""
    try:
        os.rmdir(tempfile.mkdtemp(prefix=".probe-", dir=directory))
    except OSError:
        return False
    return True


def _check_writable_ancestor(path: Path, flag: str) -> None:
    ancestor = path
    while not ancestor.exists():
        if ancestor.parent == ancestor:
            break
        ancestor = ancestor.parent
    if ancestor.exists() and not ancestor.is_dir():
        raise InputError(
            "command line", flag, f"{str(path)!r} lies under the file {str(ancestor)!r}"
        )
    if not os.access(ancestor, os.W_OK | os.X_OK) or not _can_make_in(ancestor):
        raise InputError("command line", flag, f"{str(path)!r}: cannot write in {str(ancestor)!r}")


# What a run writes into its folder (mission run --out): a folder holding any of them holds a
# run, which a new one would mix with or overwrite.
RUN_FILES = ("gcs.tlog", "records.jsonl", "summary.json", "link.json", "ground_station.log")
RUN_FILES += ("resolved-scenario.yaml",)  # what a run with overrides flew (mission.api)
RUN_FILE_PATTERNS = ("work.log", "support-*.log", "viewer.log", "g", "plots")


def run_files_in(folder: Path) -> list[Path]:
    """The files and folders of an earlier run in ``folder`` (none if it is not a folder)."""
    folder = Path(folder)
    if not folder.is_dir():
        return []
    found = [folder / name for name in RUN_FILES if (folder / name).exists()]
    for pattern in RUN_FILE_PATTERNS:
        found += sorted(folder.glob(pattern))
    return found


def remove_run_files(folder: Path) -> None:
    """Remove an earlier run's files from ``folder`` (what else it holds stays)."""
    for path in run_files_in(folder):
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path)
        else:
            path.unlink(missing_ok=True)

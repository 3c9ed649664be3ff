"""Atomic writes: the whole file or none, with the permissions the umask gives."""

from __future__ import annotations

import os
import stat

import pytest

from mission.procs.atomic import current_umask, write_atomically, write_text_atomically


@pytest.mark.parametrize("umask", [0o022, 0o077, 0o002])
def test_files_get_the_mode_the_umask_gives(tmp_path, umask):
    previous = os.umask(umask)
    try:
        assert current_umask() == umask
        write_text_atomically(tmp_path / "summary.json", "{}\n")
        plain = tmp_path / "plain.txt"
        plain.write_text("x")  # what any other file the user makes gets
    finally:
        os.umask(previous)
    mode = stat.S_IMODE((tmp_path / "summary.json").stat().st_mode)
    assert mode == 0o666 & ~umask == stat.S_IMODE(plain.stat().st_mode)


def test_a_failed_write_leaves_nothing(tmp_path):
    def fail(temp: str) -> None:
        with open(temp, "w") as handle:
            handle.write("half")
        raise RuntimeError("disk full")

    with pytest.raises(RuntimeError):
        write_atomically(tmp_path / "table.csv", fail)
    assert list(tmp_path.iterdir()) == []

"""A growing file read in pieces: every byte once, whole lines only, a missing file is no
error and costs nothing."""

from __future__ import annotations

from mission.procs.file_tail import FileTail


def test_whole_lines_come_once_and_a_line_being_written_waits(tmp_path):
    path = tmp_path / "log"
    tail = FileTail(path)
    assert tail.new_lines() == [] and tail.offset == 0  # not there yet
    path.write_bytes(b"one\ntw")
    assert tail.new_lines() == [b"one"]
    with path.open("ab") as handle:
        handle.write(b"o\nthree\n")
    assert tail.new_lines() == [b"two", b"three"]
    assert tail.new_lines() == []


def test_bytes_advance_only_as_far_as_the_reader_says(tmp_path):
    path = tmp_path / "tlog"
    path.write_bytes(b"abcdef")
    tail = FileTail(path)
    assert tail.new_bytes() == b"abcdef"
    tail.advance(4)  # "ef": an incomplete record, read again next time
    with path.open("ab") as handle:
        handle.write(b"gh")
    assert tail.new_bytes() == b"efgh"

"""STATUSTEXT longer than its 50-byte field: chunked as MAVLink 2 says, and read back whole,
through real packing and parsing."""

from __future__ import annotations

from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.link.statustext import StatusChunks, statustexts


def _through_the_wire(messages):
    sender, receiver = mavlink2.MAVLink(None, 255, 190), mavlink2.MAVLink(None)
    return [receiver.decode(bytearray(m.pack(sender))) for m in messages]


def test_a_short_text_is_one_unchunked_message():
    (message,) = statustexts("Mission complete at 257.5 s", 7)
    assert (message.id, message.chunk_seq) == (0, 0)
    assert StatusChunks().add(_through_the_wire([message])[0]) == "Mission complete at 257.5 s"


def test_a_long_text_goes_in_chunks_and_comes_back_whole():
    text = "Integrity: support-12 excluded (formation test, 14.1 m)"  # 55 bytes
    messages = statustexts(text, 3)
    assert [(m.id, m.chunk_seq) for m in messages] == [(3, 0), (3, 1)]
    chunks = StatusChunks()
    said = [chunks.add(m) for m in _through_the_wire(messages)]
    assert said == [None, text]


def test_a_text_of_whole_chunks_ends_with_an_empty_one():
    text = "x" * 100
    messages = statustexts(text, 65535)
    assert [len(m.text) for m in messages] == [50, 50, 0]
    chunks = StatusChunks()
    assert [chunks.add(m) for m in _through_the_wire(messages)] == [None, None, text]


def test_interleaved_ids_are_kept_apart():
    first, second = statustexts("a" * 60, 1), statustexts("b" * 70, 2)
    chunks = StatusChunks()
    order = [first[0], second[0], first[1], second[1]]
    said = [chunks.add(m) for m in _through_the_wire(order)]
    assert said == [None, None, "a" * 60, "b" * 70]

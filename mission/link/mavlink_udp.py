"""MAVLink 2 over UDP for both sides: encoding with pymavlink's generated classes, per-datagram
decoding that survives garbage, and a non-blocking socket endpoint with counters."""

from __future__ import annotations

import select
import socket
import time
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Any

from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.link.fast_decode import FastDecoder
from mission.link.fast_encode import FastEncoder
from mission.link.impairment import ImpairedLink, LinkSettings
from mission.link.signing import enable_signing, signing_rejections

Address = tuple[str, int]
MAX_DATAGRAM = 65_535
MAX_BATCH_BYTES = 1_400  # stay below a typical path MTU


@dataclass
class LinkCounters:
    """What a link has seen; reported by the processes at exit and in SYS_STATUS."""

    datagrams_in: int = 0
    packets_in: int = 0
    bad_datagrams: int = 0
    bad_packets: int = 0
    packets_out: int = 0
    send_errors: int = 0
    rejected: dict[str, int] = field(default_factory=dict)

    def reject(self, reason: str) -> None:
        """Count a well-formed message that was refused (out-of-range values, wrong mask...)."""
        self.rejected[reason] = self.rejected.get(reason, 0) + 1

    def summary(self) -> str:
        """One line for logs."""
        rejected = ", ".join(f"{k} {v}" for k, v in sorted(self.rejected.items())) or "none"
        return (
            f"in {self.packets_in} packets / {self.datagrams_in} datagrams, "
            f"bad {self.bad_datagrams} datagrams ({self.bad_packets} packets), "
            f"out {self.packets_out}, rejected: {rejected}"
        )


class MavlinkCodec:
    """One MAVLink 2 identity (sysid, compid): packs outgoing and parses incoming datagrams."""

    def __init__(self, system_id: int, component_id: int, signing_key: bytes | None = None) -> None:
        self.mav = mavlink2.MAVLink(None, srcSystem=system_id, srcComponent=component_id)
        self.mav.robust_parsing = True
        self.signed = signing_key is not None
        if signing_key is not None:
            enable_signing(self.mav, signing_key)
        # signed packets: pymavlink's own pack and parser; unsigned: the same bytes, sooner
        self._fast = None if self.signed else FastDecoder()
        self._encoder = None if self.signed else FastEncoder(system_id, component_id)

    @property
    def signature_rejections(self) -> int:
        """Packets refused for a missing or wrong signature (0 without signing)."""
        return signing_rejections(self.mav) if self.signed else 0

    @property
    def system_id(self) -> int:
        """This endpoint's system id."""
        return int(self.mav.srcSystem)

    def encode(self, message: Any) -> bytes:
        """Pack a generated message object as a MAVLink 2 packet from this identity."""
        if self._encoder is not None:
            packet = self._encoder.encode(message, self.mav.seq)
        else:
            packet = bytes(message.pack(self.mav))
        self.mav.seq = (self.mav.seq + 1) % 256
        return packet

    def decode(self, datagram: bytes) -> tuple[list[Any], int]:
        """Parse one UDP datagram into messages; return them and the number of bad packets.

        Parser state never carries over between datagrams: UDP keeps packets whole, so bytes
        left over at the end of a datagram are a truncated packet, counted as bad. A datagram
        of good unsigned packets takes the fast path (:mod:`mission.link.fast_decode`: the
        same messages); anything else, pymavlink's parser.
        """
        if self._fast is not None:
            messages = self._fast.decode(datagram)
            if messages is not None:
                return messages, 0
        self._reset()
        try:
            parsed = self.mav.parse_buffer(bytes(datagram)) or []
        except Exception:  # pymavlink raises several types on malformed input
            self._reset()
            return [], 1
        good = [m for m in parsed if m.get_type() != "BAD_DATA"]
        bad = len(parsed) - len(good)
        if len(self.mav.buf) - self.mav.buf_index > 0:
            bad += 1
        self._reset()
        return good, bad

    def _reset(self) -> None:
        mav = self.mav
        mav.buf = bytearray()
        mav.buf_index = 0
        mav.expected_length = mavlink2.HEADER_LEN_V1 + 2
        mav.have_prefix_error = False


class UdpEndpoint:
    """A non-blocking UDP socket carrying MAVLink for one identity."""

    def __init__(
        self,
        codec: MavlinkCodec,
        bind: Address = ("127.0.0.1", 0),
        link: LinkSettings | None = None,
        link_seed: int = 0,
        sock: socket.socket | None = None,
    ) -> None:
        """Bind a new socket to ``bind``, or take ``sock``, already bound (e.g. inherited from
        the process that started this one)."""
        self.codec = codec
        self.counters = LinkCounters()
        if sock is None:
            sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
            sock.bind(bind)
        self.sock = sock
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 21)
        self.sock.setblocking(False)
        self.link = (
            ImpairedLink(self.sock, link, link_seed) if link is not None and link.impaired else None
        )
        self._link_seed = link_seed

    def set_loss(self, loss: float) -> None:
        """Lose each datagram sent from now on with probability ``loss`` (the delay as it is);
        the drops come from the link's seeded generator, made on first use."""
        if self.link is None:
            if loss > 0:
                self.link = ImpairedLink(self.sock, LinkSettings(loss=loss), self._link_seed)
            return
        self.link.settings = replace(self.link.settings, loss=loss)

    def _transmit(self, datagram: bytes, destination: Address) -> bool:
        """One datagram out, through the impaired link if there is one."""
        if self.link is not None:
            return self.link.send(datagram, destination)
        try:
            self.sock.sendto(datagram, destination)
            return True
        except OSError:
            self.counters.send_errors += 1
            return False

    @property
    def address(self) -> Address:
        """The bound (host, port)."""
        host, port = self.sock.getsockname()[:2]
        return host, port

    def fileno(self) -> int:
        """For select()."""
        return self.sock.fileno()

    def receive(self) -> list[tuple[Any, Address]]:
        """Drain the socket; return (message, sender) pairs and count what was bad."""
        received: list[tuple[Any, Address]] = []
        while True:
            try:
                datagram, sender = self.sock.recvfrom(MAX_DATAGRAM)
            except (BlockingIOError, InterruptedError):
                return received
            except OSError:  # e.g. ICMP port unreachable surfaced on Linux
                continue
            self.counters.datagrams_in += 1
            refused = self.codec.signature_rejections
            messages, bad = self.codec.decode(datagram)
            refused = self.codec.signature_rejections - refused
            if refused:  # a refused packet parses as bad data: count it as refused instead
                self.counters.rejected["signature"] = (
                    self.counters.rejected.get("signature", 0) + refused
                )
                bad -= refused
            if bad:
                self.counters.bad_datagrams += 1
                self.counters.bad_packets += bad
            self.counters.packets_in += len(messages)
            received.extend((m, sender) for m in messages)

    def send(self, message: Any, destinations: list[Address] | tuple[Address, ...]) -> bytes:
        """Encode once and send to every destination; return the packet bytes."""
        packet = self.codec.encode(message)
        for destination in destinations:
            if self._transmit(packet, destination):
                self.counters.packets_out += 1
        return packet

    def encode(self, message: Any) -> bytes:
        """Pack a message as this endpoint's identity, to send later with
        :meth:`send_packets`."""
        return self.codec.encode(message)

    def send_packets(
        self, packets: Sequence[bytes], destinations: Sequence[Address]
    ) -> list[bytes]:
        """Send encoded packets packed into as few datagrams as fit; return the datagrams.

        MAVLink over UDP is a byte stream cut into datagrams: receivers (pymavlink, MAVProxy,
        QGroundControl, this project) parse every packet in a datagram, in order.
        """
        datagrams = pack_datagrams(packets)
        self.resend(datagrams, destinations)
        self.counters.packets_out += len(packets) * len(destinations)
        return datagrams

    def send_many(self, messages: list[Any], destinations: Sequence[Address]) -> list[bytes]:
        """Encode several messages and send them packed into as few datagrams as fit."""
        return self.send_packets([self.codec.encode(m) for m in messages], destinations)

    def resend(self, datagrams: Sequence[bytes], destinations: Sequence[Address]) -> None:
        """Send already-encoded datagrams (e.g. a step's telemetry asked for again)."""
        for destination in destinations:
            for datagram in datagrams:
                self._transmit(datagram, destination)

    def summary(self) -> str:
        """The counters, and what the impaired link dropped and delayed, in one line."""
        text = self.counters.summary()
        if self.link is not None:
            text += f", link dropped {self.link.dropped}, delayed {self.link.delayed}"
        return text

    def close(self) -> None:
        """Close the socket."""
        if self.link is not None:
            self.link.close()
        self.sock.close()


def pack_datagrams(packets: Sequence[bytes]) -> list[bytes]:
    """Packets joined into datagrams of at most MAX_BATCH_BYTES (a longer packet alone)."""
    datagrams: list[bytes] = []
    current = bytearray()
    for packet in packets:
        if current and len(current) + len(packet) > MAX_BATCH_BYTES:
            datagrams.append(bytes(current))
            current = bytearray()
        current += packet
    if current:
        datagrams.append(bytes(current))
    return datagrams


def parse_address(text: str, what: str = "address") -> Address:
    """'HOST:PORT' -> (host, port), the host an IPv4 address or a name that resolves to one
    (the links are IPv4 UDP); ValueError with a clear message otherwise."""
    host, sep, port_text = text.rpartition(":")
    if not sep or not host or not port_text.isdigit() or not 0 < int(port_text) < 65536:
        raise ValueError(f"{what} must look like HOST:PORT, got {text!r}")
    try:
        socket.getaddrinfo(host, int(port_text), socket.AF_INET, socket.SOCK_DGRAM)
    except (socket.gaierror, UnicodeError):
        raise ValueError(f"{text!r}: {host!r} is not an IPv4 address or a known host") from None
    return host, int(port_text)


class MessageQueue:
    """One message at a time from an endpoint, keeping what a drain read beyond the first."""

    def __init__(self, endpoint: UdpEndpoint) -> None:
        self.endpoint = endpoint
        self._pending: deque[tuple[Any, Address]] = deque()

    def next(self, timeout_s: float) -> tuple[Any, Address] | None:
        """The next (message, sender), waiting at most ``timeout_s``; None on timeout."""
        deadline = time.monotonic() + timeout_s
        while not self._pending:
            left = deadline - time.monotonic()
            if left <= 0:
                return None
            select.select([self.endpoint], [], [], left)
            self._pending.extend(self.endpoint.receive())
        return self._pending.popleft()

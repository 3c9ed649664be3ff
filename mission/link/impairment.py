"""A lossy, slow link for testing: drop outgoing datagrams with probability P and delay the
rest by D milliseconds (``--link-loss P --link-delay-ms D``).

Each process impairs what it sends, so giving both ends the same settings impairs both
directions. Drops come from a seeded generator (the same run loses the same datagrams, given
the same traffic); delayed datagrams leave from one background thread, in order.
"""

from __future__ import annotations

import argparse
import heapq
import itertools
import socket
import threading
import time
from dataclasses import dataclass

import numpy as np

from mission.config.errors import InputError

Address = tuple[str, int]


@dataclass(frozen=True)
class LinkSettings:
    """Loss probability and one-way delay of every datagram this process sends."""

    loss: float = 0.0
    delay_ms: float = 0.0

    def __post_init__(self) -> None:
        if not 0.0 <= self.loss < 1.0:
            raise ValueError(f"--link-loss must be in [0, 1), got {self.loss}")
        if not 0.0 <= self.delay_ms <= 10_000:
            raise ValueError(f"--link-delay-ms must be in [0, 10000], got {self.delay_ms}")

    @property
    def impaired(self) -> bool:
        """True when datagrams may be dropped or delayed."""
        return self.loss > 0 or self.delay_ms > 0


class ImpairedLink:
    """Sends datagrams through a socket, dropping and delaying them as the settings say."""

    def __init__(self, sock: socket.socket, settings: LinkSettings, seed: int) -> None:
        self.sock = sock
        self.settings = settings
        self.rng = np.random.default_rng(seed)
        self.attempted = 0
        self.dropped = 0
        self.delayed = 0
        self.send_errors = 0
        self._queue: list[tuple[float, int, bytes, Address]] = []
        self._order = itertools.count()
        self._wake = threading.Condition()
        self._closed = False
        self._thread: threading.Thread | None = None
        if settings.delay_ms > 0:
            self._thread = threading.Thread(target=self._release, daemon=True)
            self._thread.start()

    def send(self, datagram: bytes, destination: Address) -> bool:
        """Send (or drop, or queue) one datagram; False if it was dropped or failed."""
        self.attempted += 1
        if self.settings.loss > 0 and self.rng.random() < self.settings.loss:
            self.dropped += 1
            return False
        if self._thread is None:
            return self._sendto(datagram, destination)
        due = time.monotonic() + self.settings.delay_ms / 1000.0
        with self._wake:
            heapq.heappush(self._queue, (due, next(self._order), datagram, destination))
            self.delayed += 1
            self._wake.notify()
        return True

    def close(self) -> None:
        """Stop the release thread (queued datagrams are discarded)."""
        with self._wake:
            self._closed = True
            self._wake.notify()
        if self._thread is not None:
            self._thread.join(timeout=1.0)

    def _sendto(self, datagram: bytes, destination: Address) -> bool:
        try:
            self.sock.sendto(datagram, destination)
            return True
        except OSError:
            self.send_errors += 1
            return False

    def _release(self) -> None:
        while True:
            with self._wake:
                while not self._closed and (
                    not self._queue or self._queue[0][0] > time.monotonic()
                ):
                    timeout = self._queue[0][0] - time.monotonic() if self._queue else None
                    self._wake.wait(timeout)
                if self._closed:
                    return
                _, _, datagram, destination = heapq.heappop(self._queue)
            self._sendto(datagram, destination)


def add_link_arguments(parser: argparse.ArgumentParser) -> None:
    """--link-loss P and --link-delay-ms D (testing: impair every datagram this process sends)."""
    parser.add_argument(
        "--link-loss",
        type=float,
        default=0.0,
        metavar="P",
        help="drop each datagram sent with probability P (seeded; testing)",
    )
    parser.add_argument(
        "--link-delay-ms",
        type=float,
        default=0.0,
        metavar="D",
        help="delay each datagram sent by D milliseconds (testing)",
    )


def link_settings(args: argparse.Namespace) -> LinkSettings:
    """--link-loss and --link-delay-ms, checked."""
    try:
        return LinkSettings(args.link_loss, args.link_delay_ms)
    except ValueError as error:
        flag = "--link-loss" if "loss" in str(error) else "--link-delay-ms"
        raise InputError("command line", flag, str(error).split(" ", 1)[1]) from None

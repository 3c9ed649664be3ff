"""What a vehicle sends, and to whom: every peer that has talked to it lately and every --out
address. A step's telemetry leaves as one batch of datagrams, kept to be sent again when the
ground station asks for that step once more."""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator
from typing import Any

from mission.link.mavlink_udp import Address, UdpEndpoint

PEER_EXPIRY_WALL_S = 30.0


class Outbox:
    """A vehicle's sending side over its endpoint."""

    def __init__(self, endpoint: UdpEndpoint, outs: list[Address]) -> None:
        self.endpoint = endpoint
        self.outs = list(outs)
        self.peers: dict[Address, float] = {}  # each peer, and when it was last heard
        self._batch: list[Any] | None = None
        self._step_events: list[Any] | None = None  # collecting what the vehicle says as it steps
        self._said: list[Any] = []  # what the step said, sent with its telemetry
        # The last step's messages, for a repeated tick: encoded afresh when asked again, since
        # a signed link refuses a replayed packet (its signature timestamp must increase).
        self._last_step: list[Any] = []

    def heard(self, sender: Address, now: float) -> bool:
        """``sender`` talked to us at ``now``; True if it is a new peer."""
        new = sender not in self.peers
        self.peers[sender] = now
        return new

    def expire_peers(self, now: float) -> None:
        """Forget the peers silent for :data:`PEER_EXPIRY_WALL_S`."""
        for peer, seen in list(self.peers.items()):
            if now - seen > PEER_EXPIRY_WALL_S:
                del self.peers[peer]

    def broadcast(self, message: Any) -> None:
        """Send a message to every peer that has talked to us and every --out address.

        While a step is being published, messages are collected and leave together; what the
        vehicle says while it steps (faults, parameters, contacts) leaves with that step's
        telemetry, beside its marker, so that it is as reliable as the lockstep: a step whose
        marker was lost is sent again, and carries it again.
        """
        if self._step_events is not None:
            self._step_events.append(message)
        elif self._batch is not None:
            self._batch.append(message)
        else:
            self.endpoint.send(message, [*self.peers, *self.outs])

    @contextlib.contextmanager
    def stepping(self) -> Iterator[None]:
        """While the vehicle steps: what it says is kept for the step's telemetry."""
        self._step_events = []
        try:
            yield
        finally:
            self._said, self._step_events = self._step_events, None

    def publish_step(self, publish: Callable[[], None]) -> None:
        """What ``publish`` broadcasts (the step's telemetry) as one batch of datagrams."""
        said, self._said, self._batch = self._said, [], []
        try:
            publish()
        finally:
            # What the step said goes just before the marker (SYSTEM_TIME, the last): in the
            # marker's datagram, so that a marker received means they were received.
            batch, self._batch = self._batch[:-1] + said + self._batch[-1:], None
            self.endpoint.send_many(batch, [*self.peers, *self.outs])
            self._last_step = batch

    @property
    def has_last_step(self) -> bool:
        """Whether a step has been published (and can be sent again)."""
        return bool(self._last_step)

    def resend_last_step(self, to: Address) -> None:
        """The last step's batch again, to ``to`` alone."""
        self.endpoint.send_many(self._last_step, [to])

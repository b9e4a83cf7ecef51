"""Thin layer over cyclonedds 0.10.2: one participant per session, raw-CDR write and take.

Raw I/O (ddspy_write / ddspy_take on already-serialized bytes) lets the backend skip the pure
Python serializer (see wire.py); the topic still carries the IDL type, so discovery, type names
and the robot's view of the topic are exactly those of the @final unitree_hg types.
This module imports cyclonedds at import time: import it only from connect()/open().
"""

from __future__ import annotations

import threading
from typing import Any

from cyclonedds._clayer import ddspy_take, ddspy_write
from cyclonedds.core import InstanceState, Listener, ReadCondition, SampleState, ViewState, WaitSet
from cyclonedds.domain import Domain, DomainParticipant
from cyclonedds.pub import DataWriter
from cyclonedds.qos import Policy, Qos
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration

# Same shape as Unitree's SDK config: bind to one NIC by name, or by IP when it contains a dot.
_IFACE_XML = """<?xml version="1.0" encoding="UTF-8" ?>
<CycloneDDS><Domain Id="any"><General><Interfaces>
  <NetworkInterface {attr}="{value}" priority="default" multicast="default"/>
</Interfaces></General></Domain></CycloneDDS>"""

# A Cyclone domain can be configured once per process; remember what we configured it with.
_DOMAINS: dict[int, tuple[str | None, Any]] = {}
_DOMAINS_LOCK = threading.Lock()
# cyclonedds fills a type's XTypes data lazily on its first Topic and not thread-safely (two threads at
# once: AttributeError or a crash; serve's chest light and the backend's connect did): one at a time.
_TOPICS_LOCK = threading.Lock()


def describe(domain_id: int, network_interface: str | None) -> str:
    return f"domain {domain_id}, interface {network_interface or 'Cyclone default'}"


def _ensure_domain(domain_id: int, network_interface: str | None) -> None:
    with _DOMAINS_LOCK:
        if domain_id in _DOMAINS:
            if _DOMAINS[domain_id][0] != network_interface:
                raise RuntimeError(
                    f"DDS domain {domain_id} is already configured in this process for interface "
                    f"{_DOMAINS[domain_id][0]!r}; cannot reconfigure it for {network_interface!r}"
                )
            return
        domain = None
        if network_interface:
            attr = "address" if "." in network_interface else "name"
            domain = Domain(domain_id, _IFACE_XML.format(attr=attr, value=network_interface))
        _DOMAINS[domain_id] = (network_interface, domain)


def queue_qos(depth: int) -> Qos:
    """Reliable, keep-last-depth: for test receivers that must not miss or overwrite a sample."""
    return Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepLast(depth))


class MatchCounter:
    """Counts matched remote endpoints via listener callbacks (0.10.2 has no status getter)."""

    def __init__(self) -> None:
        self.count = 0
        self._changed = threading.Condition()

    def on_publication_matched(self, _writer: Any, status: Any) -> None:
        self._set(status.current_count)

    def on_subscription_matched(self, _reader: Any, status: Any) -> None:
        self._set(status.current_count)

    def _set(self, count: int) -> None:
        with self._changed:
            self.count = count
            self._changed.notify_all()

    def wait(self, timeout_s: float) -> bool:
        with self._changed:
            return self._changed.wait_for(lambda: self.count > 0, timeout=timeout_s)

    def listener(self) -> Listener:
        return Listener(
            on_publication_matched=self.on_publication_matched,
            on_subscription_matched=self.on_subscription_matched,
        )


class RawReader:
    """A DataReader plus a waitset, returning the serialized samples (CDR bytes with header)."""

    def __init__(
        self, participant: DomainParticipant, topic: Topic, qos: Qos | None = None
    ) -> None:
        self.matched = MatchCounter()
        self.reader = DataReader(participant, topic, qos=qos, listener=self.matched.listener())
        mask = SampleState.Any | ViewState.Any | InstanceState.Any
        self._condition = ReadCondition(self.reader, mask)
        self._waitset = WaitSet(participant)
        self._waitset.attach(self._condition)

    def take(self, timeout_s: float, max_samples: int = 64) -> list[bytes]:
        """Wait up to timeout_s for data, then take everything available (oldest first)."""
        return [data for data, _ in self.take_stamped(timeout_s, max_samples)]

    def take_stamped(self, timeout_s: float, max_samples: int = 64) -> list[tuple[bytes, int]]:
        """Same, each with its source timestamp: when the writer wrote it (ns since the epoch)."""
        self._waitset.wait(duration(seconds=timeout_s))
        got = ddspy_take(self._condition._ref, max_samples)
        if isinstance(got, int):
            return []
        return [(data, info.source_timestamp) for data, info in got if info.valid_data]

    def take_typed(self, timeout_s: float, max_samples: int = 16) -> list[Any]:
        """Same, deserialized with the library (for low-rate RPC messages)."""
        self._waitset.wait(duration(seconds=timeout_s))
        return [
            s
            for s in self.reader.take(max_samples, condition=self._condition)
            if s.sample_info.valid_data
        ]


class RawWriter:
    def __init__(self, participant: DomainParticipant, topic: Topic) -> None:
        self.matched = MatchCounter()
        self.writer = DataWriter(participant, topic, listener=self.matched.listener())

    def write(self, cdr: bytes) -> None:
        ret = ddspy_write(self.writer._ref, cdr)
        if ret < 0:
            raise RuntimeError(
                f"DDS write failed on {self.writer.topic.get_name()} (return code {ret})"
            )

    def write_typed(self, sample: Any) -> None:
        self.writer.write(sample)


class DdsSession:
    """One participant and its topics; close() drops every entity it created."""

    def __init__(self, domain_id: int, network_interface: str | None) -> None:
        _ensure_domain(domain_id, network_interface)
        self.domain_id = domain_id
        self.network_interface = network_interface
        self.participant: DomainParticipant | None = DomainParticipant(domain_id)
        self._topics: dict[str, Topic] = {}

    def _topic(self, name: str, data_type: type) -> Topic:
        with _TOPICS_LOCK:
            if name not in self._topics:
                self._topics[name] = Topic(self.participant, name, data_type)
            return self._topics[name]

    def reader(self, name: str, data_type: type, qos: Qos | None = None) -> RawReader:
        """Default QoS (as Unitree's SDK uses) unless given: best effort, keep last 1."""
        return RawReader(self.participant, self._topic(name, data_type), qos)

    def writer(self, name: str, data_type: type) -> RawWriter:
        return RawWriter(self.participant, self._topic(name, data_type))

    def describe(self) -> str:
        return describe(self.domain_id, self.network_interface)

    def close(self) -> None:
        # Deleting the participant deletes its readers, writers and topics in the C library.
        participant, self.participant = self.participant, None
        self._topics.clear()
        if participant is not None:
            participant.__del__()

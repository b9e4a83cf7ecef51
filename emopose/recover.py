"""python -m emopose.recover FILE [OUT]: rewrite a torn MCAP (its writer was killed: kill -9, a power cut)
into a complete one that the official reader accepts.

The Recorder closes and fsyncs a chunk every FLUSH_S (emopose/recording.py), so a torn file holds every
message but those of the chunk in progress. This reads the file's records in order up to where it
breaks, and writes its schemas, channels, metadata and messages again, indexed and with a footer. OUT
defaults to FILE with `.recovered.mcap` in place of `.mcap`; FILE is never changed.
"""

from __future__ import annotations

import struct
import sys
from dataclasses import dataclass
from pathlib import Path

from mcap.exceptions import McapError
from mcap.records import Channel, Message, Metadata, Schema
from mcap.stream_reader import StreamReader
from mcap.writer import Writer

# What a torn tail raises while it is read: a record cut short, a chunk that does not decompress.
TORN = (McapError, EOFError, struct.error, ValueError, OSError)


@dataclass(frozen=True)
class Recovered:
    out: Path
    messages: int
    channels: int
    complete: bool  # the input had its footer: nothing was torn


def _records(path: Path) -> tuple[list, bool]:
    """The records readable from the start of the file, and whether its end was reached intact."""
    records = []
    with path.open("rb") as f:
        try:
            for record in StreamReader(f, emit_chunks=False, validate_crcs=True).records:
                records.append(record)
        except TORN:
            return records, False
    return records, True


def recover(path: str | Path, out: str | Path | None = None) -> Recovered:
    """Write every readable message of `path` into `out` (a complete MCAP)."""
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"recover: {path} does not exist")
    target = (
        Path(out) if out is not None else path.with_name(path.name.removesuffix(".mcap") + ".recovered.mcap")
    )
    if target.resolve() == path.resolve():
        raise ValueError(f"recover: OUT must differ from FILE ({path})")
    records, complete = _records(path)
    if not records:
        raise ValueError(f"recover: {path} is not an MCAP file (no readable record)")
    schemas, channels, messages = {}, {}, 0
    with target.open("wb") as stream:
        writer = Writer(stream)
        writer.start(profile="", library="emopose recover")
        for record in records:
            if isinstance(record, Schema):
                schemas[record.id] = writer.register_schema(record.name, record.encoding, record.data)
            elif isinstance(record, Channel):
                channels[record.id] = writer.register_channel(
                    record.topic, record.message_encoding, schemas.get(record.schema_id, 0), record.metadata
                )
            elif isinstance(record, Metadata):
                writer.add_metadata(record.name, record.metadata)
            elif isinstance(record, Message) and record.channel_id in channels:
                writer.add_message(
                    channels[record.channel_id],
                    record.log_time,
                    record.data,
                    record.publish_time,
                    record.sequence,
                )
                messages += 1
        writer.finish()
    return Recovered(target, messages, len(channels), complete)


def main(argv: list[str]) -> int:
    if len(argv) not in (1, 2):
        print("usage: python -m emopose.recover FILE [OUT]", file=sys.stderr)
        return 2
    try:
        done = recover(*argv)
    except (ValueError, OSError) as exc:
        print(str(exc), file=sys.stderr)
        return 2
    state = "was complete" if done.complete else "was torn"
    print(
        f"recovered {done.messages} messages on {done.channels} channels into {done.out} (the input {state})"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

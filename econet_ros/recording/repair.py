"""Recovering a bag whose writer was killed (SIGKILL, power loss): its MCAP file has no footer
and no summary, and the folder no metadata.yaml, but every chunk written before holds complete
records (schemas, channels, messages). ``repair`` reads those chunks in order, stops at the
first incomplete record, and writes what they hold as a new, whole bag. ROS-free.

MCAP records (mcap.dev spec): opcode (1 byte), length (uint64), content. A chunk (0x06) holds
schema (0x03), channel (0x04) and message (0x05) records; other records are skipped.
"""
from __future__ import annotations

import struct
from dataclasses import dataclass
from pathlib import Path

from ..errors import BagError
from .bags import BagWriter

MAGIC = b"\x89MCAP0\r\n"
CHUNK, SCHEMA, CHANNEL, MESSAGE = 0x06, 0x03, 0x04, 0x05


@dataclass
class Recovered:
    """What the complete chunks of an MCAP file hold."""

    topics: dict[int, tuple[str, str]]         # channel id -> (topic, message type)
    messages: list[tuple[int, int, bytes]]     # (channel id, log time ns, CDR bytes)
    chunks: int
    lost_bytes: int                            # after the last complete record


class _Cursor:
    """Reads MCAP's little-endian primitives from a buffer."""

    def __init__(self, data: bytes | memoryview, offset: int = 0):
        self.data, self.at = memoryview(data), offset

    def take(self, fmt: str):
        values = struct.unpack_from("<" + fmt, self.data, self.at)
        self.at += struct.calcsize("<" + fmt)
        return values if len(values) > 1 else values[0]

    def raw(self, size: int) -> memoryview:
        self.at += size
        return self.data[self.at - size:self.at]

    def text(self) -> str:
        return bytes(self.raw(self.take("I"))).decode("utf-8")


def _records(data: memoryview, start: int = 0):
    """(opcode, content) of each complete record; the cursor's end offset goes last."""
    cursor = _Cursor(data, start)
    while cursor.at + 9 <= len(data):
        opcode, length = cursor.take("BQ")
        if cursor.at + length > len(data):
            cursor.at -= 9
            break
        yield opcode, cursor.raw(length)
    yield None, cursor.at


def recover(mcap: Path) -> Recovered:
    """Schemas, channels and messages of the complete chunks of an MCAP file."""
    data = memoryview(Path(mcap).read_bytes())
    if len(data) < len(MAGIC) or bytes(data[:len(MAGIC)]) != MAGIC:
        raise BagError(f"{mcap} is empty or not an MCAP file: nothing to recover")
    schemas: dict[int, str] = {}
    found = Recovered({}, [], 0, 0)
    for opcode, content in _records(data, len(MAGIC)):
        if opcode is None:                     # a whole file ends in the magic again
            tail = bytes(data[content:])
            found.lost_bytes = 0 if tail == MAGIC else len(tail)
        elif opcode == CHUNK:
            found.chunks += 1
            _read_chunk(content, schemas, found)
    return found


def _read_chunk(content: memoryview, schemas: dict[int, str], found: Recovered) -> None:
    cursor = _Cursor(content)
    cursor.take("QQQI")                       # start, end, uncompressed size, crc
    if cursor.text():
        raise BagError("the bag's chunks are compressed; repair reads uncompressed ones only")
    records = cursor.raw(cursor.take("Q"))
    for opcode, record in _records(records):
        if opcode == SCHEMA:
            inner = _Cursor(record)
            schema = inner.take("H")
            schemas[schema] = inner.text()
        elif opcode == CHANNEL:
            inner = _Cursor(record)
            channel, schema = inner.take("HH")
            found.topics[channel] = (inner.text(), schemas.get(schema, ""))
        elif opcode == MESSAGE:
            channel, _, log_time, _ = struct.unpack_from("<HIQQ", record)
            found.messages.append((channel, log_time, bytes(record[22:])))


def mcap_of(bag: Path) -> Path:
    """The MCAP file of a bag folder (or the file itself)."""
    bag = Path(bag)
    if bag.is_file():
        return bag
    files = sorted(bag.glob("*.mcap")) if bag.is_dir() else []
    if len(files) != 1:
        raise BagError(f"{bag}: expected one .mcap file in the folder, found {len(files)}")
    return files[0]


def repair(bag: Path, out: Path) -> tuple[int, Recovered]:
    """Write the complete chunks of a damaged bag as the new bag ``out``; returns (messages
    written, what was found)."""
    found = recover(mcap_of(bag))
    if not found.messages:
        raise BagError(f"{bag}: no complete chunk with messages: nothing to recover")
    if Path(out).exists():
        raise BagError(f"{out} exists already (a bag is a new folder)")
    topics = {topic: msgtype for topic, msgtype in found.topics.values()}
    names = {channel: topic for channel, (topic, _) in found.topics.items()}
    custom = {"econet.repaired_from": str(bag),
              "econet.note": f"recovered from {found.chunks} complete chunk(s); "
                             f"{found.lost_bytes} bytes after them were incomplete"}
    with BagWriter(Path(out), topics, custom) as writer:
        for channel, t_ns, data in sorted(found.messages, key=lambda m: m[1]):
            writer.write(names[channel], t_ns, data)
    return len(found.messages), found

"""The lockstep messages as serialized CDR bytes, written and read with numpy.

rclpy can publish bytes that are already serialized and hand a ``raw=True`` subscription the
bytes it received. For the big batched lockstep messages that skips building a Python message,
converting it to C and back (about 0.1 ms per message here, more than the transport itself), and
the arrays are read in place with ``np.frombuffer``. The bytes on the wire are exactly what
rclpy would send for the same message, so typed subscribers (a recorder, a user's node, RViz)
receive ordinary messages.

``Codec(Retina)`` reads the field list from the generated message class, so it follows the
``.msg`` files; it handles what those messages hold: fixed-size numbers and bools, and unbounded
sequences of them (XCDR1, little endian, as rmw_fastrtps writes them).
"""
from __future__ import annotations

import itertools
import struct
from typing import Any

import numpy as np

from ..errors import WireError

HEADER = b"\x00\x01\x00\x00"      # encapsulation: plain CDR, little endian

_TRIAL_AND_CYCLE = struct.Struct("<II")


def trial_and_cycle(data) -> tuple[int, int]:
    """(trial, cycle) of a serialized econet sensor or command message, without decoding it:
    both are the first two uint32 fields, right after the CDR header (little-endian assumed,
    as every ROS 2 middleware here writes). For TrialStart: (trial, cycles)."""
    return _TRIAL_AND_CYCLE.unpack_from(data, len(HEADER))


_NUMBERS = {
    "boolean": np.dtype(np.bool_), "octet": np.dtype(np.uint8), "uint8": np.dtype(np.uint8),
    "int8": np.dtype(np.int8), "uint16": np.dtype("<u2"), "int16": np.dtype("<i2"),
    "uint32": np.dtype("<u4"), "int32": np.dtype("<i4"), "uint64": np.dtype("<u8"),
    "int64": np.dtype("<i8"), "float": np.dtype("<f4"), "double": np.dtype("<f8"),
}
_LENGTH = struct.Struct("<I")
_ZEROS = bytes(8)                  # alignment padding: at most 7 bytes


class Codec:
    """Encode keyword values to CDR bytes and decode CDR bytes to a dict, for one message type.
    Decoded sequences are read-only numpy views into the received bytes (no copy)."""

    def __init__(self, msg_class):
        self.name = msg_class.__name__
        self.fields: list[tuple[str, np.dtype, bool]] = []
        for name, kind in msg_class.get_fields_and_field_types().items():
            sequence = kind.startswith("sequence<") and kind.endswith(">")
            dtype = _NUMBERS.get(kind[len("sequence<"):-1] if sequence else kind)
            if dtype is None:
                raise TypeError(f"{self.name}.{name}: {kind} is not supported by the codec")
            self.fields.append((name, dtype, sequence))
        # The numbers before the first sequence sit at fixed offsets: one unpack reads them
        # (a third of the time of reading them one by one).
        self.head_names, codes, offset = [], [], 0
        for name, dtype, sequence in itertools.takewhile(lambda f: not f[2], self.fields):
            pad = -offset % dtype.itemsize
            codes.append(f"{pad}x{'?' if dtype.kind == 'b' else dtype.char}")
            offset += pad + dtype.itemsize
            self.head_names.append(name)
        self.head = struct.Struct("<" + "".join(codes))

    def encode(self, **values: Any) -> bytes:
        """Serialized message; missing fields are zero / empty, as in a default message."""
        unknown = set(values) - {name for name, _, _ in self.fields}
        if unknown:
            raise TypeError(f"{self.name} has no field(s) {', '.join(sorted(unknown))}")
        parts = [HEADER]
        offset = 0                     # alignment counts from the end of the header

        def put(data, size: int, align: int) -> None:
            nonlocal offset
            pad = -offset % align
            if pad:
                parts.append(_ZEROS[:pad])
            parts.append(data)
            offset += pad + size

        for name, dtype, sequence in self.fields:
            value = values.get(name)
            if sequence:
                items = np.ascontiguousarray(() if value is None else value, dtype=dtype)
                put(_LENGTH.pack(items.size), 4, 4)
                # the array's own buffer: join() then copies each array exactly once
                put(items.reshape(-1).view(np.uint8).data, items.nbytes,
                    dtype.itemsize)              # aligned even when empty
            else:
                put(np.array(0 if value is None else value, dtype=dtype).tobytes(),
                    dtype.itemsize, dtype.itemsize)
        return b"".join(parts)

    def decode(self, data: bytes) -> dict[str, Any]:
        """Field values by name: Python numbers and bools, numpy arrays for sequences."""
        if data[:4] != HEADER:
            raise WireError(f"not a little-endian plain-CDR {self.name} message")
        view = memoryview(data)[4:]
        try:
            out = dict(zip(self.head_names, self.head.unpack_from(view)))
            offset = self.head.size
            for name, dtype, sequence in self.fields[len(out):]:
                if sequence:
                    offset += -offset % 4
                    (count,) = _LENGTH.unpack_from(view, offset)
                    offset += 4
                    offset += -offset % dtype.itemsize
                    out[name] = np.frombuffer(view, dtype, count, offset)
                    offset += count * dtype.itemsize
                else:
                    offset += -offset % dtype.itemsize
                    out[name] = np.frombuffer(view, dtype, 1, offset)[0].item()
                    offset += dtype.itemsize
        except (ValueError, struct.error) as error:
            raise WireError(f"truncated {self.name} message ({len(data)} bytes): "
                            f"{error}") from None
        return out

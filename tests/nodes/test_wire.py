"""The lockstep messages written and read with numpy (econet_ros.nodes.wire) are the bytes rclpy
itself reads and writes."""
import numpy as np
import pytest
from rclpy.serialization import deserialize_message, serialize_message

from econet_msgs.msg import MuscleCommand, Proprioception, Retina, Touch
from econet_ros.nodes.wire import Codec, WireError

LOCKSTEP = (Retina, Proprioception, Touch, MuscleCommand)


def random_fields(codec: Codec, n: int, rng) -> dict:
    """Values for every field; sequences of n (odd n tests the padding after them)."""
    values = {}
    for name, dtype, sequence in codec.fields:
        if sequence:
            values[name] = rng.random(n) if dtype.kind == "f" else \
                rng.integers(0, 2, n).astype(dtype)
        elif dtype.kind == "b":
            values[name] = bool(rng.integers(2))
        else:
            values[name] = int(rng.integers(0, 2 ** 31))
    return values


@pytest.mark.parametrize("msg_type", LOCKSTEP, ids=lambda t: t.__name__)
@pytest.mark.parametrize("n", [0, 1, 3, 8, 2001])
def test_encode_is_read_by_rclpy_and_decode_reads_rclpy(msg_type, n):
    codec = Codec(msg_type)
    values = random_fields(codec, n, np.random.default_rng(n))
    ours = codec.encode(**values)
    msg = deserialize_message(ours, msg_type)
    for name, value in values.items():
        assert np.array_equal(np.asarray(getattr(msg, name)), np.asarray(value)), name
    theirs = serialize_message(msg)
    assert len(theirs) == len(ours)
    decoded = codec.decode(theirs)
    assert list(decoded) == list(values)
    for name, value in values.items():
        assert np.array_equal(np.asarray(decoded[name]), np.asarray(value)), name


def test_missing_fields_are_defaults_and_unknown_fields_are_refused():
    codec = Codec(Touch)
    assert deserialize_message(codec.encode(), Touch) == Touch()
    with pytest.raises(TypeError, match="no field"):
        codec.encode(colour=3)


def test_truncated_or_foreign_bytes_are_wire_errors():
    codec = Codec(Retina)
    data = codec.encode(n_envs=4, activation=np.ones(32), fixated=np.ones(4, np.uint8))
    with pytest.raises(WireError, match="truncated"):
        codec.decode(data[:40])
    with pytest.raises(WireError, match="plain-CDR"):
        codec.decode(b"\x00\x00\x00\x00" + data[4:])


def test_arrays_are_written_row_major_whatever_their_memory_layout():
    """The world hands over views (the retina is a column slice of its sense array) and bools
    for uint8 fields; both must reach the wire as the row-major values rclpy would send."""
    senses = np.random.default_rng(0).random((5, 13))
    vision = senses[:, :8]                          # not contiguous
    fixated = np.array([True, False, True, True, False])
    data = Codec(Retina).encode(n_envs=5, units_per_env=8, activation=vision, fixated=fixated)
    msg = deserialize_message(data, Retina)
    assert np.array_equal(np.asarray(msg.activation), vision.reshape(-1))
    assert np.array_equal(np.asarray(msg.fixated), fixated.astype(np.uint8))
    assert data == serialize_message(msg)

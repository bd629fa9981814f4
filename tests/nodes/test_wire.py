"""The lockstep messages written and read with numpy (econet_ros.nodes.wire), and written in place
by the nodes' kernels (econet_ros.nodes.lockstep_wire), are the bytes rclpy itself reads and writes."""
import numpy as np
import pytest
from rclpy.serialization import deserialize_message, serialize_message

from econet_msgs.msg import MuscleCommand, Proprioception, Retina, Touch
from econet_ros.config import Config
from econet_ros.nodes.lockstep_wire import FIELDS, CommandMessage, SensorMessages
from econet_ros.nodes.wire import Codec, WireError, trial_and_cycle
from econet_ros.topics import COMMAND, SENSORS, command_fields, sensor_fields
from econet_ros.world import World, sample_setups

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


@pytest.mark.parametrize("msg_type", LOCKSTEP, ids=lambda t: t.__name__)
def test_trial_and_cycle_read_without_decoding_match_rclpy(msg_type):
    msg = msg_type(trial=70001, cycle=99, n_envs=2)
    assert trial_and_cycle(serialize_message(msg)) == (70001, 99)


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


# -- the bytes the nodes write in place (econet_ros.nodes.lockstep_wire) -------------------------------
def test_the_in_place_layout_lists_the_fields_of_the_generated_classes():
    for part, msg_type in zip((*SENSORS, COMMAND), LOCKSTEP):
        ours = [(name, np.dtype(code.removesuffix("[]")), code.endswith("[]"))
                for name, code in FIELDS[part]]
        assert ours == Codec(msg_type).fields, part


@pytest.mark.parametrize("n", [1, 3, 2001])
def test_the_world_kernel_writes_the_bytes_the_codec_writes(n):
    """For random trials, commands and heads: the messages the world's kernel writes while it
    steps are the Codec's serialisation of the same cycle, and the world moves as World.step
    moves it."""
    model = Config().model
    rng = np.random.default_rng(n)
    setup = sample_setups(rng, n, model)
    plain, written = World(n, model), World(n, model)
    plain.reset(setup)
    written.reset(setup)
    wire = SensorMessages(n, model.visual_units)
    trial = int(rng.integers(0, 2 ** 32))
    wire.write(written, trial, False)
    assert wire.encoded() == codec_sensors(plain.observe(), trial, False)
    for cycle in range(12):
        motor = rng.random((n, 5)) * 1.4 - 0.2           # beyond [0, 1] too: clipped
        trial, final = int(rng.integers(0, 2 ** 32)), bool(rng.integers(2))
        expected = plain.step(motor)
        got = wire.step(written, motor, trial, final)
        assert wire.encoded() == codec_sensors(expected, trial, final), cycle
        for name in ("body", "shoulder", "elbow", "senses", "fixated"):
            assert np.array_equal(getattr(written, name), getattr(plain, name)), name
        assert got.cycle == expected.cycle
    with pytest.raises(ValueError, match="NaN"):
        wire.step(written, np.full((n, 5), np.nan), 0, False)


def test_the_command_written_in_place_is_the_codec_s():
    rng = np.random.default_rng(5)
    command = CommandMessage(7)
    for _ in range(3):              # the buffer is reused: nothing of the last one stays
        trial, cycle, motor = int(rng.integers(0, 2 ** 32)), int(rng.integers(0, 2 ** 32)), \
            rng.random((7, 5))
        assert command.encode(trial, cycle, motor) == \
            Codec(MuscleCommand).encode(**command_fields(trial, cycle, motor))


def codec_sensors(obs, trial: int, final: bool) -> dict[str, bytes]:
    return {part: Codec(msg_type).encode(**fields) for (part, fields), msg_type in
            zip(sensor_fields(obs, trial, final).items(), LOCKSTEP)}

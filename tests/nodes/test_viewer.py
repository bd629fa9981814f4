"""The viewer node, as its own process next to a world free-running at a fixed rate, both in the
root namespace, so that the topics are those docs/foxglove-layout.json names. A Foxglove
WebSocket client (the `websockets` library speaking the protocol) connects as the open-source
Foxglove app, Lichtblick, does, sees every layout topic advertised with ROS 2 schemas,
subscribes, and decodes what it receives; one that offers only the old subprotocol is refused.
And the world pictures every cycle when the display rate equals its rate."""
import asyncio
import json
import os
import re
import struct
import time

import pytest

from econet_ros.recording.messages import typestore

from graph_helpers import REPO, ros_session, spin_until

pytestmark = pytest.mark.ros       # every test here starts ROS nodes

# What Lichtblick (1.22.0 and later) offers, in its order; the server picks the one it speaks.
APP_SUBPROTOCOLS = ["foxglove.websocket.v1", "foxglove.sdk.v1"]
SERVED_SUBPROTOCOL = "foxglove.sdk.v1"
MESSAGE_DATA = 0x01       # server -> client binary opcode: subscription id, log time, payload
LAYOUT = REPO / "docs" / "foxglove-layout.json"
SCHEMAS = {"/markers": "visualization_msgs/msg/MarkerArray",
           "/joint_states": "sensor_msgs/msg/JointState",
           "/touch": "econet_msgs/msg/Touch",
           "/tf_static": "tf2_msgs/msg/TFMessage"}
WORLD_RATE_HZ = 20


@pytest.fixture(scope="module")
def ros(tmp_path_factory):
    yield from ros_session(tmp_path_factory, 45 + os.getpid() % 15, "viewer")


@pytest.fixture(scope="module")
def port(ros):
    """A world at WORLD_RATE_HZ with as many pictures a second, and the viewer; its port."""
    rclpy, executor, procs = ros
    world, world_log = procs.start("world", "/", "mode:=free", f"rate_hz:={WORLD_RATE_HZ}",
                                   f"display_rate_hz:={WORLD_RATE_HZ}", "trial_cycles:=0")
    viewer, log = procs.start("viewer", "/", "port:=0")
    for proc, out, line in ((world, world_log, "world ready"), (viewer, log, "serving")):
        spin_until(executor, lambda: line in out.read_text() or proc.poll() is not None,
                   timeout=90, what=line)
    assert SERVED_SUBPROTOCOL in log.read_text()           # the start-up line names it
    yield int(re.search(r"ws://127\.0\.0\.1:(\d+)", log.read_text()).group(1))
    assert viewer.poll() is None


def layout_topics() -> set[str]:
    """Every topic the layout names: 3D panel topics, message paths (/topic.field[0]) and topic
    paths."""
    topics = set()

    def walk(node, key=None):
        if isinstance(node, dict):
            if isinstance(node.get("topics"), dict):
                topics.update(node["topics"])
            for name, value in node.items():
                walk(value, name)
        elif isinstance(node, list):
            for value in node:
                walk(value, key)
        elif key in ("value", "topicPath"):
            topics.add(re.match(r"/[\w/]*", node).group(0))

    walk(json.loads(LAYOUT.read_text())["configById"])
    return topics


async def watch(port: int, topics: tuple[str, ...], wanted: int) -> tuple[str, dict, dict]:
    """Connect as the app does, subscribe to `topics` and collect `wanted` messages of each:
    returns the chosen subprotocol, the advertised channels by topic and the received payloads
    by topic."""
    import websockets

    async with websockets.connect(f"ws://127.0.0.1:{port}",
                                  subprotocols=APP_SUBPROTOCOLS) as ws:
        channels = {}
        while not set(topics) <= set(channels):
            frame = await asyncio.wait_for(ws.recv(), 30)
            if isinstance(frame, str) and json.loads(frame)["op"] == "advertise":
                channels.update({c["topic"]: c for c in json.loads(frame)["channels"]})
        by_id = dict(enumerate(topics))
        await ws.send(json.dumps({"op": "subscribe", "subscriptions": [
            {"id": k, "channelId": channels[topic]["id"]} for k, topic in by_id.items()]}))
        received = {topic: [] for topic in topics}
        while min(len(v) for v in received.values()) < wanted:
            frame = await asyncio.wait_for(ws.recv(), 30)
            if isinstance(frame, bytes) and frame[0] == MESSAGE_DATA:
                subscription, _ = struct.unpack_from("<IQ", frame, 1)
                received[by_id[subscription]].append(frame[13:])
        return ws.subprotocol, channels, received


def test_the_app_sees_every_layout_topic_with_data(port):
    in_layout = layout_topics()
    assert {"/markers", "/joint_states", "/touch"} <= in_layout     # the walk finds them
    topics = tuple(sorted(in_layout | {"/tf_static"}))
    subprotocol, channels, received = asyncio.run(watch(port, topics, wanted=2))
    assert subprotocol == SERVED_SUBPROTOCOL
    assert set(channels) == set(SCHEMAS)
    for topic, schema in SCHEMAS.items():
        assert (channels[topic]["encoding"], channels[topic]["schemaEncoding"],
                channels[topic]["schemaName"]) == ("cdr", "ros2msg", schema)
    store = typestore()
    markers = store.deserialize_cdr(received["/markers"][0], SCHEMAS["/markers"])
    assert [m.ns for m in markers.markers] == ["arm", "hand", "eye_field", "object"]
    assert markers.markers[0].header.frame_id == "econet"
    joints = store.deserialize_cdr(received["/joint_states"][0], SCHEMAS["/joint_states"])
    assert list(joints.name) == ["body", "shoulder", "elbow"] and len(joints.position) == 3
    touches = [store.deserialize_cdr(data, SCHEMAS["/touch"]) for data in received["/touch"]]
    assert {(t.n_envs, len(t.contact)) for t in touches} == {(1, 1)}
    assert touches[0].cycle < touches[1].cycle
    (transform,) = store.deserialize_cdr(received["/tf_static"][0],
                                         SCHEMAS["/tf_static"]).transforms
    assert (transform.header.frame_id, transform.child_frame_id) == ("map", "econet")


def test_help_names_the_subprotocol_and_the_apps_that_speak_it():
    from econet_ros.nodes import viewer_node
    from econet_ros.nodes.runner import usage

    text = " ".join(usage("viewer_node", viewer_node.__doc__, viewer_node.PARAMETERS).split())
    for words in ("subprotocol is foxglove.sdk.v1", "foxglove.websocket.v1 is refused",
                  "A current Foxglove app and Lichtblick 1.22.0 or later"):
        assert words in text


def test_a_client_offering_only_the_old_subprotocol_is_refused(port):
    import websockets

    async def connect():
        async with websockets.connect(f"ws://127.0.0.1:{port}",
                                      subprotocols=["foxglove.websocket.v1"]):
            pass

    with pytest.raises(websockets.exceptions.InvalidStatus) as refused:
        asyncio.run(connect())
    assert refused.value.response.status_code == 400


def test_every_cycle_is_pictured_when_the_rates_match(ros, port):
    """Over a few seconds as many pictures as cycles (a wall-clock throttle lost about a third
    of them to timer jitter)."""
    rclpy, executor, _ = ros
    from econet_ros.nodes import graph

    node = rclpy.create_node("picture_counter")
    executor.add_node(node)
    cycles, pictures = [], []
    every = graph.QOS["lockstep_reader"]       # keep all: the counter itself loses none
    for topic, received in (("touch", cycles), ("joint_states", pictures)):
        node.create_subscription(graph.message_class(topic), topic, received.append, every,
                                 raw=True)

    def count_for(seconds: float) -> tuple[int, int]:
        cycles.clear()
        pictures.clear()
        started = time.monotonic()
        spin_until(executor, lambda: time.monotonic() - started > seconds, what="the count")
        return len(cycles), len(pictures)

    spin_until(executor, lambda: cycles and pictures, what="both subscriptions matched")
    count_for(1.0)                             # until both arrive as they are sent
    n_cycles, n_pictures = count_for(3.0)
    assert n_cycles >= WORLD_RATE_HZ          # the world ran (at least a third of its rate)
    assert abs(n_pictures - n_cycles) <= 2, (n_cycles, n_pictures)

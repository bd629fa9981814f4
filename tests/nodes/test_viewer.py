"""The viewer node, as its own process next to a free-running world: a Foxglove WebSocket client
(the `websockets` library speaking the protocol the Foxglove app speaks) sees the display
topics and /tf_static advertised with ROS 2 schemas, subscribes, and decodes what it receives."""
import asyncio
import json
import os
import re
import struct

import pytest

from econet_ros.recording.messages import typestore

from graph_helpers import ros_session, spin_until

pytestmark = pytest.mark.ros       # every test here starts ROS nodes

SUBPROTOCOL = "foxglove.sdk.v1"
MESSAGE_DATA = 0x01       # server -> client binary opcode: subscription id, log time, payload


@pytest.fixture(scope="module")
def ros(tmp_path_factory):
    yield from ros_session(tmp_path_factory, 45 + os.getpid() % 15, "viewer")


async def watch(port: int, topics: tuple[str, ...], wanted: int) -> tuple[dict, dict]:
    """Connect, subscribe to `topics` and collect `wanted` messages of each: returns the
    advertised channels by topic and the received payloads by topic."""
    import websockets

    async with websockets.connect(f"ws://127.0.0.1:{port}", subprotocols=[SUBPROTOCOL]) as ws:
        channels = {}
        while not set(topics) <= set(channels):
            frame = await asyncio.wait_for(ws.recv(), 30)
            if isinstance(frame, str) and json.loads(frame)["op"] == "advertise":
                channels.update({c["topic"]: c for c in json.loads(frame)["channels"]})
        by_id = {k: topic for k, topic in enumerate(topics)}
        await ws.send(json.dumps({"op": "subscribe", "subscriptions": [
            {"id": k, "channelId": channels[topic]["id"]} for k, topic in by_id.items()]}))
        received = {topic: [] for topic in topics}
        while min(len(v) for v in received.values()) < wanted:
            frame = await asyncio.wait_for(ws.recv(), 30)
            if isinstance(frame, bytes) and frame[0] == MESSAGE_DATA:
                subscription, _ = struct.unpack_from("<IQ", frame, 1)
                received[by_id[subscription]].append(frame[13:])
        return channels, received


def test_viewer_serves_the_pictures_over_foxglove_websocket(ros):
    rclpy, executor, procs = ros
    ns = "/view"
    procs.start("world", ns, "mode:=free", "rate_hz:=50")
    viewer, log = procs.start("viewer", ns, "port:=0")
    spin_until(executor, lambda: "serving" in log.read_text() or viewer.poll() is not None,
               what="the viewer to serve")
    port = int(re.search(r"ws://127\.0\.0\.1:(\d+)", log.read_text()).group(1))
    topics = (f"{ns}/markers", f"{ns}/joint_states", "/tf_static")
    channels, received = asyncio.run(watch(port, topics, wanted=2))
    store = typestore()
    for topic in topics:
        assert channels[topic]["encoding"] == "cdr"
        assert channels[topic]["schemaEncoding"] == "ros2msg"
    markers = [store.deserialize_cdr(data, channels[topics[0]]["schemaName"])
               for data in received[topics[0]]]
    assert [m.ns for m in markers[0].markers] == ["arm", "hand", "eye_field", "object"]
    assert markers[0].markers[0].header.frame_id == "econet"
    joints = store.deserialize_cdr(received[topics[1]][0], "sensor_msgs/msg/JointState")
    assert list(joints.name) == ["body", "shoulder", "elbow"] and len(joints.position) == 3
    (transform,) = store.deserialize_cdr(received["/tf_static"][0],
                                         "tf2_msgs/msg/TFMessage").transforms
    assert (transform.header.frame_id, transform.child_frame_id) == ("map", "econet")
    assert viewer.poll() is None

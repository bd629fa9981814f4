"""The viewer node: serves the graph's pictures to the Foxglove app over the Foxglove WebSocket
protocol (foxglove-sdk), so a running graph can be watched without any ROS tool:
    scripts/node viewer            # then, in Foxglove: Open connection -> ws://localhost:8765
Its WebSocket subprotocol is foxglove.sdk.v1, the Foxglove SDK's: a client that offers only the
older foxglove.websocket.v1 is refused (HTTP 400). A current Foxglove app and Lichtblick 1.22.0
or later offer foxglove.sdk.v1; Foxglove Studio 1.x and Lichtblick up to 1.21 offer only the
older name and cannot connect: upgrade them.

Subscribes  joint_states, markers (raw, display QoS); touch (raw, display QoS: newest only)
Serves      ws://<host>:<port> with one channel per topic (CDR, ros2msg schemas: the app decodes
            them as from a ROS 2 connection) and /tf_static, which puts the pictures' frame at
            the origin of `map` (recording/display.py), sent again every second so that an app
            that connects later has it too. docs/foxglove-layout.json lays the app out.

Besides the pictures only touch is forwarded, and only its newest message with each picture:
the lockstep topics carry every environment every cycle, which a view does not need.
"""
from __future__ import annotations

import sys
import time

import foxglove
from rclpy.node import Node

from ..recording import display
from ..recording.messages import typestore
from ..topics import DISPLAY, TF_STATIC, TOPICS
from . import graph
from .runner import Param, declare_parameters, run_node

PARAMETERS = (
    Param("host", "127.0.0.1", "address to serve on (127.0.0.1: this machine only)"),
    Param("port", 8765, "WebSocket port (0 = any free port; the log line names it)", low=0,
          high=65535),
)
FRAME_EVERY_SEC = 1.0
SUBPROTOCOL = "foxglove.sdk.v1"      # what foxglove-sdk serves (no setting): named in the log
FORWARDED = (*DISPLAY, "touch")


def _channel(topic: str, msgtype: str) -> foxglove.Channel:
    """A Foxglove channel that carries a ROS 2 message type as CDR bytes."""
    definition = typestore().generate_msgdef(msgtype, ros_version=2)[0]
    return foxglove.Channel(topic, message_encoding="cdr", schema=foxglove.Schema(
        name=msgtype, encoding="ros2msg", data=definition.encode("utf-8")))


class ViewerNode(Node):
    def __init__(self, **node_options):
        """node_options go to rclpy's Node (e.g. cli_args, as graph_node gives them)."""
        super().__init__("viewer", **node_options)
        v = declare_parameters(self, PARAMETERS)
        self.server = foxglove.start_server(name="econet", host=v["host"], port=v["port"])
        self.channels = {topic: _channel(self.resolve_topic_name(topic), TOPICS[topic].type)
                         for topic in FORWARDED}
        self.frame_channel = _channel(TF_STATIC.name, TF_STATIC.type)
        self.framed_at = -FRAME_EVERY_SEC
        for topic in DISPLAY:
            graph.subscription(self, topic, lambda data, t=topic: self._forward(t, data),
                               raw=True)
        self.touch: bytes | None = None      # the newest contacts, sent with the next picture
        self.create_subscription(graph.message_class("touch"), "touch", self._keep_touch,
                                 graph.QOS["display"], raw=True)
        self.get_logger().info(f"serving {', '.join(self.channels)} on "
                               f"ws://{v['host']}:{self.server.port} (WebSocket subprotocol "
                               f"{SUBPROTOCOL}: a current Foxglove app, Lichtblick 1.22.0 or "
                               "later)")

    def _forward(self, topic: str, data: bytes) -> None:
        now = time.time_ns()
        if time.monotonic() - self.framed_at >= FRAME_EVERY_SEC:
            self.framed_at = time.monotonic()
            self.frame_channel.log(display.tf_static(display.frame_of(topic, data), now),
                                   log_time=now)
        self.channels[topic].log(bytes(data), log_time=now)
        if topic == "markers" and self.touch is not None:
            self.channels["touch"].log(self.touch, log_time=now)
            self.touch = None

    def _keep_touch(self, data: bytes) -> None:
        self.touch = data

    def destroy_node(self):
        self.server.stop()
        return super().destroy_node()


def main(args: list[str] | None = None) -> int:
    return run_node("viewer_node", ViewerNode, args, parameters=PARAMETERS, doc=__doc__)


if __name__ == "__main__":
    sys.exit(main())

"""The recorder node: writes the graph's lockstep and display topics to a rosbag2 bag (MCAP,
metadata.yaml version 9) while it runs, for graphs started by hand (``ros2 bag record`` is not
available from PyPI; on a ROS 2 machine ``ros2 bag record`` of the same topics works too).

Subscribes  trial_start, retina, proprioception, touch, muscle_command, joint_states, markers
            (or the `topics` parameter's subset), raw: messages are stored as they arrive

It says "recording" only once every recorded topic has a matched publisher and those have had
half a second to match it back (before that, "waiting for publishers of ..."), so that what is
started after that line is in the bag from its first message. Ctrl-C or SIGTERM closes the
bag, which then opens and holds everything recorded before; a recorder killed outright
(SIGKILL, power loss) leaves a bag without metadata.yaml that loses at most the last second:
``econet bag repair BAG`` recovers it.
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

from rclpy.node import Node

from ..errors import BagError, ConfigError
from .runner import Param, declare_parameters, run_node, serve
from .topic_recorder import ALL_TOPICS, TopicRecorder

# A subscription sees its publishers before they see it (each side learns of the other on its
# own; here up to a tenth of a second under load), and a publisher sends only to readers it has
# seen: "recording" waits this long after the subscriptions matched.
MATCH_SETTLE_SEC = 0.5

PARAMETERS = (
    Param("out", "", "bag folder to create (must not exist); empty = "
                     "bags/econet-YYYYmmdd-HHMMSS"),
    Param("topics", ",".join(ALL_TOPICS), "comma-separated topics to record (relative names)"),
)


class RecorderNode(Node):
    def __init__(self, **node_options):
        """node_options go to rclpy's Node (e.g. cli_args, as graph_node gives them)."""
        super().__init__("recorder", **node_options)
        v = declare_parameters(self, PARAMETERS)
        out, topics = v["out"], v["topics"]
        self.out = Path(out or time.strftime("bags/econet-%Y%m%d-%H%M%S"))
        if self.out.exists():
            raise ConfigError(f"bag {self.out} exists already (a bag is a new folder)")
        names = [t.strip() for t in topics.split(",") if t.strip()]
        if not names:
            raise ConfigError("topics is empty")
        self.recorder = TopicRecorder(self, names)
        try:
            self.out.parent.mkdir(parents=True, exist_ok=True)
            self.recorder.start(self.out, {"econet.source": "recorder_node"})
        except OSError as error:
            raise BagError(f"cannot create bag {self.out}: {error.strerror or error}") from None
        self.names = names
        unmatched = self.recorder.unmatched()     # none where the graph shares the process
        self.get_logger().info(f"bag {self.out} open" + (
            f"; waiting for publishers of {', '.join(unmatched)}" if unmatched else ""))
        self.matched_at: float | None = None
        self.waiting = self.create_timer(0.05, self._check_matched)

    def _check_matched(self) -> None:
        """Say "recording" once every recorded topic has a matched publisher, and the
        publishers have had MATCH_SETTLE_SEC to match this node's subscriptions in turn."""
        if self.recorder.unmatched():
            self.matched_at = None
            return
        now = time.monotonic()
        if self.matched_at is None:
            self.matched_at = now
        if now - self.matched_at >= MATCH_SETTLE_SEC:
            self.waiting.cancel()
            self.get_logger().info(f"recording {', '.join(self.names)} to {self.out}")

    def ready(self) -> bool:
        """Whether it records (said "recording"): what is published from now on is in the bag."""
        return self.waiting.is_canceled()

    def close(self, executor=None) -> None:
        """Close the bag; with the executor that serves this node, first take what had arrived
        (after a signal, or in a composed graph after the evolution)."""
        try:
            if executor is not None:
                _drain(self.recorder, executor)
        finally:
            self.recorder.stop()
            print(f"recorder_node: bag closed: {self.out}", file=sys.stderr)


def _body(node: RecorderNode, executor) -> int:
    try:
        serve(executor, timeout_sec=0.2)
    except BaseException:
        node.close()                  # an error: the bag closes with what it has
        raise
    node.close(executor)
    return 0


def _drain(recorder: TopicRecorder, executor, most_sec: float = 1.0) -> None:
    """After a signal: take what had arrived before it (until nothing comes for 50 ms, at
    most a second), so that the bag holds every message sent before the signal."""
    deadline = time.monotonic() + most_sec
    while time.monotonic() < deadline:
        before = recorder.received
        executor.spin_once(timeout_sec=0.05)
        if recorder.received == before:
            return


def main(args: list[str] | None = None) -> int:
    return run_node("recorder_node", RecorderNode, args, body=_body, parameters=PARAMETERS,
                    doc=__doc__)


if __name__ == "__main__":
    sys.exit(main())

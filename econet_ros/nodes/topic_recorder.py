"""Recording topics of the graph into rosbag2 bags (econet_ros.bags), shared by the recorder
node and the supervisor. Subscriptions are raw (``raw=True``): the serialized CDR bytes go
into the bag as they arrived, nothing is decoded."""
from __future__ import annotations

from collections import Counter
from pathlib import Path

from rclpy.node import Node

from ..errors import ConfigError
from ..recording.bags import BagWriter, header
from ..topics import LOCKSTEP, RECORDED, TOPICS
from . import graph

ALL_TOPICS = RECORDED


class TopicRecorder:
    """Raw subscriptions to ``topics``; while a bag is open every message goes into it."""

    def __init__(self, node: Node, topics=ALL_TOPICS):
        unknown = [t for t in topics if t not in RECORDED]
        if unknown:
            raise ConfigError(f"cannot record topic(s) {', '.join(unknown)} (choose from "
                                   f"{', '.join(ALL_TOPICS)})")
        self.node = node
        self.topics = tuple(topics)
        self.names = {t: node.resolve_topic_name(t) for t in self.topics}
        self.writer: BagWriter | None = None
        self.heard: Counter = Counter()       # (topic, trial) -> sensor/command messages
        self.min_trial = 0      # drop econet messages of earlier trials (late stragglers)
        for topic in self.topics:
            graph.subscription(node, topic, lambda data, t=topic: self._on(t, data), raw=True)

    def start(self, path: Path, custom: dict[str, str] | None = None,
              min_trial: int = 0) -> BagWriter:
        self.stop()
        self.min_trial = min_trial
        self.heard.clear()
        self.writer = BagWriter(path, {self.names[t]: TOPICS[t].type for t in self.topics},
                                custom)
        return self.writer

    def stop(self) -> None:
        """Close the bag (idempotent); metadata.yaml is written now."""
        writer, self.writer = self.writer, None
        if writer is not None:
            writer.close()

    def _on(self, topic: str, data: bytes) -> None:
        if self.writer is None:
            return
        econet = topic in LOCKSTEP or topic == "trial_start"
        trial = header(data)[0] if econet else None
        if econet and trial < self.min_trial:
            return
        self.writer.write(self.names[topic], self.node.get_clock().now().nanoseconds, data)
        if econet:
            self.heard[topic, trial] += 1

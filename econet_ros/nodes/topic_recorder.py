"""Recording topics of the graph into rosbag2 bags (econet_ros.recording.bags), shared by the
recorder node and the supervisor. Subscriptions are raw (``raw=True``): the serialized CDR bytes
go into the bag as they arrived, nothing is decoded but the (trial, cycle) header.

What goes in, so that a bag reads as documented (docs/bags.md):
- a trial's ``trial_start`` right before the trial's first sensor or command message, and only
  for trials that have some (a recorder that joins late receives the recent starts as history);
- display pictures only after the bag's first ``trial_start``, so none of an earlier trial
  comes first;
- a /tf_static for the pictures' frame before the first of them (the frame read from it);
- everything on disk every FLUSH_SEC, so that a recorder killed outright loses at most the
  last second (``econet bag repair`` makes such a bag whole again).
"""
from __future__ import annotations

from collections import Counter
from pathlib import Path

from rclpy.node import Node

from ..errors import ConfigError
from ..recording import display
from ..recording.bags import BagWriter
from ..topics import DISPLAY, LOCKSTEP, RECORDED, TF_STATIC, TOPICS
from . import graph
from .wire import trial_and_cycle

ALL_TOPICS = RECORDED
FLUSH_SEC = 0.5


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
        self.heard: Counter = Counter()       # (topic, trial) -> messages written
        self.min_trial = 0      # drop econet messages of earlier trials (late stragglers)
        self.starts: dict[int, tuple[int, bytes]] = {}   # trial -> its trial_start, unwritten
        self.shown = False      # a trial_start is in the bag: display pictures may follow
        self.framed = False     # the pictures' /tf_static is in the bag
        self.received = 0       # messages taken, in or out of a bag
        self.lockstep_recorded = any(t in LOCKSTEP for t in self.topics)
        self.subscriptions = {topic: graph.subscription(
            node, topic, lambda data, t=topic: self._on(t, data), raw=True)
            for topic in self.topics}
        node.create_timer(FLUSH_SEC, self.flush)

    def unmatched(self) -> list[str]:
        """Recorded topics that no publisher has matched yet (nothing can arrive on them)."""
        return [t for t, sub in self.subscriptions.items() if sub.get_publisher_count() == 0]

    def start(self, path: Path, custom: dict[str, str] | None = None,
              min_trial: int = 0) -> BagWriter:
        self.stop()
        self.min_trial = min_trial
        self.heard.clear()
        self.starts.clear()
        self.shown = self.framed = False
        self.writer = BagWriter(path, {TF_STATIC.name: TF_STATIC.type,
                                       **{self.names[t]: TOPICS[t].type for t in self.topics}},
                                custom)
        return self.writer

    def flush(self) -> None:
        if self.writer is not None:
            self.writer.flush()

    def stop(self) -> None:
        """Close the bag (idempotent); metadata.yaml is written now."""
        writer, self.writer = self.writer, None
        if writer is not None:
            writer.close()

    def _on(self, topic: str, data: bytes) -> None:
        self.received += 1
        if self.writer is None:
            return
        now = self.node.get_clock().now().nanoseconds
        if topic in DISPLAY:
            if self.shown:
                if not self.framed:
                    self.writer.write(TF_STATIC.name, now,
                                      display.tf_static(display.frame_of(topic, data), now))
                    self.framed = True
                self._write(topic, now, data)
            return
        trial = trial_and_cycle(data)[0]
        if trial < self.min_trial:
            return
        if topic == "trial_start":
            if self.lockstep_recorded:
                self.starts[trial] = (now, data)
            else:                          # nothing to wait for: in it goes
                self._write(topic, now, data, trial)
                self.shown = True
            return
        if trial in self.starts:
            self._write("trial_start", *self.starts.pop(trial), trial)
            self.shown = True
            self.starts = {k: v for k, v in self.starts.items() if k > trial}
        self._write(topic, now, data, trial)

    def _write(self, topic: str, t_ns: int, data: bytes, trial: int | None = None) -> None:
        self.writer.write(self.names[topic], t_ns, data)
        if trial is not None and (topic in LOCKSTEP or topic == "trial_start"):
            self.heard[topic, trial] += 1

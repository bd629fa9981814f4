"""The supervisor's Evaluator (the contract of evolution.Evaluator): tests a generation through
the world and controller nodes instead of in process, with exactly the in-process trial starts,
weights and noise, so that ``runs.evolve_into`` writes the same result folders either way. It
hears only touch, so it scores fitness but records no per-cycle trace.

Per batch of trials it swaps the controller's weights (set_weights), starts the trials in the
world (reset_trials), lets world and controller run the cycles in lockstep and scores fitness
from the touch topic it hears, from its world only (graph.Partner). A batch that cannot finish
(a node vanished, nothing moved) is run again from its start once the graph is back; so is a
batch during which the graph was more than one world, one controller and this supervisor (a
second publisher of a lockstep topic, a second server or client of a service: a stranger that
could have changed the results). Batches are deterministic, so nothing changes.
"""
from __future__ import annotations

import shutil
import time
from pathlib import Path

import numpy as np
from rclpy.node import Node

from ..config import Config
from ..errors import GraphError
from ..evolution import (Evaluator, GenerationResult, generation_setups, genome_weights,
                         noise_seed, score_generation)
from ..topics import COMMAND, LOCKSTEP, SENSORS, SERVICES
from ..trials import Record, TrialMeasures
from ..world import TrialSetup
from . import graph
from .runner import check_stop


# How often, at most, a running batch looks at the graph (about 0.1 ms for all topics and
# services); once more after its last cycle.
GRAPH_CHECK_SEC = 0.02
# Who publishes each lockstep topic (named in the log when nothing does).
ROLES = {"retina": "world", "proprioception": "world", "touch": "world",
         COMMAND: "controller"}


class BatchFailed(GraphError):
    """A batch of trials could not finish through the graph; it is run again from its start."""


class GraphEvaluator(Evaluator):
    """Tests generations through the graph for ``node`` (the supervisor); ``controller`` is
    the name the controller node must run (set_weights refuses otherwise; empty: any)."""

    def __init__(self, node: Node, config: Config, controller: str, n_weights: int,
                 stall_timeout: float, service_timeout: float, recorder=None):
        self.node, self.config, self.controller = node, config, controller
        self._n_weights = n_weights
        self.stall_timeout, self.service_timeout = stall_timeout, service_timeout
        self.recorder = recorder
        self.executor = None                 # set once the node is spinning
        self.touch: dict[int, dict[int, np.ndarray]] = {}   # trial -> cycle -> contact
        self.repeats = 0
        self.recorded_trial = -1
        self.checked_graph = 0.0
        self.world = graph.Partner(node, "touch", graph.RateLimitedLog(node))
        graph.subscription(node, "touch", self._on_touch, raw=True, with_publisher=True)
        self.set_weights = graph.client(node, "set_weights")
        self.reset_trials = graph.client(node, "reset_trials")

    # -- the Evaluator contract -------------------------------------------------------------
    @property
    def n_weights(self) -> int:
        return self._n_weights

    def trial_setups(self, seed: int, run: int, generation: int) -> TrialSetup:
        return generation_setups(self.config, seed, run, generation)

    def test_generation(self, genomes: np.ndarray, seed: int, run: int, generation: int,
                        record: Record = False) -> GenerationResult:
        if record:
            raise GraphError(f"the graph evaluator records no per-cycle trace (record={record!r}): "
                             "re-test the generation in process (runs.replay) for one")
        setup = self.trial_setups(seed, run, generation)
        requests = self.requests(genomes, setup, seed, run, generation)
        contact = self.run_batch(*requests, where=f"run {run} generation {generation}")
        return score_generation(self.config, generation, genomes,
                                TrialMeasures.from_contact(contact))

    # -- batches of trials ------------------------------------------------------------------
    def requests(self, genomes: np.ndarray, setup: TrialSetup, seed: int, run: int,
                 generation: int):
        """The weight swap (one network per econet, each driving its block of trials) and the
        reset that start a batch of trials exactly as the in-process engine would."""
        weights = genome_weights(self.config, genomes)
        weights_request = graph.service_class("set_weights").Request(
            n_envs=len(setup), weights_per_network=weights.shape[1],
            weights=graph.f64(weights), noise_seed=noise_seed(seed, run, generation),
            network=self.controller)
        reset_request = graph.service_class("reset_trials").Request(
            n_envs=len(setup), cycles=self.config.evolution.cycles, seed=0,
            object_xy=graph.f64(setup.object_xy), body_deg=graph.f64(setup.body),
            shoulder_deg=graph.f64(setup.shoulder), elbow_deg=graph.f64(setup.elbow))
        return weights_request, reset_request

    def run_batch(self, weights_request, reset_request, where: str, bag: Path | None = None,
                  custom: dict | None = None) -> np.ndarray:
        """(cycles, n_envs) contact history of one batch, retried until it finishes; with
        ``bag``, the attempt that finishes is recorded (as <bag>.partial/<name>, moved to
        <bag> when complete, so that its MCAP file is <name>.mcap)."""
        attempt = 0
        while True:
            attempt += 1
            partial = bag.parent / f"{bag.name}.partial" / bag.name if bag else None
            try:
                if partial:
                    shutil.rmtree(partial.parent, ignore_errors=True)
                    partial.parent.mkdir(parents=True)
                    # messages of trials before the next reset are stragglers (a retry may
                    # follow a restarted world, whose trials count from 1 again)
                    self.recorder.start(partial, custom,
                                        min_trial=self.recorded_trial + 1 if attempt == 1 else 0)
                contact = self._run_once(weights_request, reset_request)
                if partial:
                    self._finish_recording(reset_request.cycles)
                    self.recorder.stop()
                    partial.rename(bag)
                    partial.parent.rmdir()
                return contact
            except BatchFailed as why:
                self.node.get_logger().warning(
                    f"{where}: {why}; testing the {'recording' if bag else 'generation'} again "
                    f"(attempt {attempt + 1})")
                self.wait_for_graph()
            finally:
                if self.recorder is not None:
                    self.recorder.stop()

    def _run_once(self, weights_request, reset_request) -> np.ndarray:
        self._check_graph("before the batch")
        reply = self._call(self.set_weights, weights_request, "set_weights")
        if not reply.success:
            raise GraphError(f"the controller refused the weights: {reply.message}")
        self.touch.clear()
        reply = self._call(self.reset_trials, reset_request, "reset_trials")
        if not reply.success:
            raise GraphError(f"the world refused the reset: {reply.message}")
        self.recorded_trial = reply.trial
        return self._contact(reply.trial, reset_request.cycles, reset_request.n_envs)

    def _contact(self, trial: int, cycles: int, n: int) -> np.ndarray:
        """Spin until touch of cycles 0..cycles of ``trial`` is in; its contact history.

        The stall clock restarts only when a cycle not heard before comes in: the world sends a
        stalled cycle again every second, and a repeat is no progress."""
        for other in [t for t in self.touch if t != trial]:
            del self.touch[other]
        heard = self.touch.setdefault(trial, {})
        known, advanced_at = len(heard), time.monotonic()
        while len(heard) < cycles + 1:
            self._spin_once()
            heard = self.touch.setdefault(trial, {})
            if len(heard) > known:
                known, advanced_at = len(heard), time.monotonic()
            self._check_running(advanced_at, len(heard) - 1, cycles)
        self._check_graph(f"after cycle {cycles} of {cycles}")
        contact = np.empty((cycles, n), dtype=bool)
        for t in range(1, cycles + 1):
            if len(heard[t]) != n:
                raise BatchFailed(f"touch for cycle {t} has {len(heard[t])} environments, "
                                  f"expected {n}")
            contact[t - 1] = heard[t] != 0
        del self.touch[trial]
        return contact

    def _check_running(self, advanced_at: float, cycle: int, cycles: int) -> None:
        """BatchFailed if the batch cannot finish (no new cycle since ``advanced_at``), or the
        graph is not one world, one controller and this supervisor any more (looked at every
        GRAPH_CHECK_SEC)."""
        if time.monotonic() - advanced_at > self.stall_timeout:
            raise BatchFailed(f"no new cycle for {self.stall_timeout:g} s after cycle {cycle} of "
                              f"{cycles} (controller or world gone?)")
        if time.monotonic() - self.checked_graph > GRAPH_CHECK_SEC:
            self._check_graph(f"at cycle {cycle} of {cycles}")

    def _check_graph(self, when: str) -> None:
        self.checked_graph = time.monotonic()
        problems = self.graph_problems()
        if problems:
            raise BatchFailed(f"{'; '.join(problems)} {when}")

    def graph_problems(self) -> list[str]:
        """What keeps the graph from being one world, one controller and this supervisor: a
        node missing, or a second publisher of a lockstep topic, server or client of a service
        (another graph on this ROS domain and namespace, a stray node, or a killed node that
        stays listed until its DDS lease runs out). Empty when all is well."""
        problems = []
        for topic in LOCKSTEP:
            count = self.node.count_publishers(topic)
            if count == 0:
                problems.append(f"no {ROLES[topic]} (nothing publishes {topic})")
            elif count > 1:
                names = sorted(graph.node_of(info) for info in
                               self.node.get_publishers_info_by_topic(
                                   self.node.resolve_topic_name(topic)))
                problems.append(f"{count} publishers of {topic} (nodes {', '.join(names)})")
        for service in SERVICES:
            servers, clients = (self.node.count_services(service),
                                self.node.count_clients(service))
            if servers != 1:
                problems.append(f"{servers} servers of {service}")
            if clients != 1:
                problems.append(f"{clients} clients of {service} (this supervisor is one)")
        return problems

    def _finish_recording(self, cycles: int) -> None:
        """After the last touch: wait until the trial's other sensor messages are recorded."""
        trial, heard = self.recorded_trial, self.recorder.heard

        def done():
            return all(heard[part, trial] >= cycles + 1 for part in SENSORS) and \
                heard[COMMAND, trial] >= cycles
        if not self.spin_until(done, self.service_timeout):
            raise BatchFailed("the recording missed messages of the trial")
        self.spin_until(lambda: False, 0.2)     # the last display pictures

    # -- plumbing ---------------------------------------------------------------------------
    def _on_touch(self, data: bytes, publisher: bytes) -> None:
        """A serialized Touch message (see wire), counted only if it comes from the world."""
        if not self.world.accepts(publisher):
            return
        msg = graph.decode(self.node, "touch", data)
        if msg is None:
            return
        trial, cycle = msg["trial"], msg["cycle"]
        cycles = self.touch.setdefault(trial, {})
        if cycle in cycles and not np.array_equal(cycles[cycle], msg["contact"]):
            self.repeats += 1
            self.node.get_logger().error(f"lockstep broken: cycle {cycle} of trial {trial} "
                                         "arrived twice, different")
        cycles[cycle] = msg["contact"]          # the same again: the world sent it again

    def spin_until(self, done, timeout: float) -> bool:
        deadline = time.monotonic() + timeout
        while not done():
            if time.monotonic() > deadline:
                return False
            self._spin_once()
        return True

    def _spin_once(self) -> None:
        """Serve callbacks for a moment; Stopped (ends the node quietly) after a signal."""
        check_stop()
        self.executor.spin_once(timeout_sec=0.05)

    def _call(self, client, request, what: str):
        if not client.service_is_ready():
            raise BatchFailed(f"the {what} service is not available")
        future = client.call_async(request)
        if not self.spin_until(future.done, self.service_timeout):
            raise BatchFailed(f"no reply from {what} within {self.service_timeout:g} s")
        return future.result()

    def wait_for_graph(self) -> None:
        """Block until the graph is one world, one controller and this supervisor, with both
        services ready; saying what is wrong whenever that changes, and every 5 s."""
        said, said_at = "", 0.0
        while True:
            problems = self.graph_problems()
            if not problems and self.set_weights.service_is_ready() and \
                    self.reset_trials.service_is_ready():
                return
            why = "; ".join(problems) or "services not ready"
            if why != said or time.monotonic() - said_at > 5.0:
                self.node.get_logger().warning(f"waiting for the graph: {why}")
                said, said_at = why, time.monotonic()
            self.spin_until(lambda: False, 0.1)

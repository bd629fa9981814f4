"""The supervisor node: runs the paper's evolutionary experiment through the graph.

Per generation it swaps the controller's weights (set_weights), starts the generation's trials
in the world (reset_trials), lets world and controller run the cycles in lockstep, scores
fitness from the touch topic it hears, and selects and reproduces with the model core. It writes
the same result folders as `econet evolve` (econet_ros.results.RunStore); a generation is
written only once it is complete, so an interrupted one is simply tested again (generations are
deterministic).

With record_every = N > 0 it also records the best econet of generations 0, N, 2N, ... and the
last one: after the generation is written it runs that econet's trials once more (same starts,
same weights, same noise seed) with every lockstep and display topic recorded into a rosbag2
bag, <record_dir>/run-RR/gen-GGGG (see econet_ros.bags).

Subscribes  touch (econet_msgs/Touch); when recording also trial_start, retina,
            proprioception, muscle_command, joint_states, markers (raw)
Publishes   progress (econet_msgs/EvolutionProgress), one message per finished generation
Calls       set_weights (econet_msgs/SetWeights), reset_trials (econet_msgs/ResetTrials)
"""
from __future__ import annotations

import json
import shutil
import sys
import time
from pathlib import Path

import numpy as np
from rclpy.duration import Duration
from rclpy.node import Node

from econet_msgs.msg import EvolutionProgress, Touch
from econet_msgs.srv import ResetTrials, SetWeights

from .. import genome
from ..cli import UsageError, check_writable
from ..config import CONDITIONS, Config, ConfigError
from ..engine import TrialMeasures
from ..plugins import PluginError, resolve
from ..evolution import (Evaluator, GenerationResult, initial_genomes, next_generation,
                         noise_seed, score_generation)
from ..experiment import run_folder, summarize
from ..results import RunStore
from . import common
from .common import NodeError


class GenerationFailed(Exception):
    """A generation could not finish through the graph (a node vanished, a reply was refused,
    nothing moved); it is tested again from its start."""


class Refused(Exception):
    """A node refused a request for a reason retrying cannot fix (e.g. wrong network)."""


class SupervisorNode(Node):
    def __init__(self, **node_options):
        """node_options go to rclpy's Node (e.g. namespace, parameter_overrides)."""
        super().__init__("supervisor", **node_options)
        e = Config().evolution
        p = {
            "config": ("", "JSON config file (as econet --config); the options below override "
                           "it"),
            "condition": (e.condition, "normal, three-layer or random (the controller node's "
                                       "network must match)"),
            "generations": (e.generations, "generations per run"),
            "population": (e.population, "econets per generation"),
            "parents": (e.parents, "econets selected to reproduce"),
            "trials": (e.trials, "trials per econet per generation"),
            "cycles": (e.cycles, "movement cycles per trial"),
            "seed": (1, "base random seed; a run is a pure function of it"),
            "runs": (1, "independent runs, written to out/run-01, run-02, ..."),
            "out": ("results/graph", "output folder (same layout as econet evolve --out)"),
            "controller": ("", "controller the controller node runs, if not the condition's "
                               "network: a registered name or module:Class (its n_params "
                               "sizes the genomes)"),
            "record_every": (0, "record the best econet's trials as a bag every this many "
                                "generations (and the last); 0 = never"),
            "record_dir": ("", "folder of the bags; empty = <out>/bags"),
            "overwrite": (False, "delete out/run-* first instead of resuming them"),
            "stall_timeout_sec": (3.0, "test a generation again when no cycle arrives for this "
                                       "long"),
            "service_timeout_sec": (5.0, "wait this long for a service reply before retrying"),
            "linger_sec": (1.0, "stay this long after the last generation so that late "
                                "monitors receive the final progress messages"),
        }
        v = {name: common.declare(self, name, default, text)
             for name, (default, text) in p.items()}
        self.v = v
        if v["condition"] not in CONDITIONS:
            raise NodeError(f"condition must be one of {', '.join(CONDITIONS)}, "
                            f"got '{v['condition']}'")
        if v["runs"] < 1 or v["seed"] < 0:
            raise NodeError("runs must be at least 1 and seed at least 0")
        base = common.node_config(v["config"])
        try:
            self.config = base.replace(**{f"evolution.{k}": v[k] for k in (
                "condition", "generations", "population", "parents", "trials", "cycles")})
        except ConfigError as error:
            raise NodeError(str(error)) from None
        self.out = Path(v["out"])
        try:
            check_writable(self.out)
        except UsageError as error:
            raise NodeError(str(error)) from None
        self.network = v["controller"] or v["condition"]
        try:
            controller = resolve(self.network)(1, self.config) if v["controller"] else None
        except PluginError as error:
            raise NodeError(str(error)) from None
        if v["record_every"] < 0:
            raise NodeError(f"record_every must be 0 or more, got {v['record_every']}")
        # the core's trial starts and weight count
        self.evaluator = Evaluator(self.config, controller=controller)
        self.record_dir = Path(v["record_dir"]) if v["record_dir"] else self.out / "bags"
        self.recorder = None
        self._recorded_trial = -1
        if v["record_every"]:
            from .recording import TopicRecorder
            self.recorder = TopicRecorder(self)

        self.touch: dict[int, dict[int, np.ndarray]] = {}   # trial -> cycle -> contact
        self.last_touch = time.monotonic()
        self.repeats = 0
        self.create_subscription(Touch, common.TOUCH, self._on_touch, common.LOCKSTEP_QOS,
                                 raw=True)
        self.pub_progress = self.create_publisher(EvolutionProgress, common.PROGRESS,
                                                  common.PROGRESS_QOS)
        self.set_weights = self.create_client(SetWeights, common.SET_WEIGHTS)
        self.reset_trials = self.create_client(ResetTrials, common.RESET_TRIALS)
        self.executor_ = None

    # -- plumbing -----------------------------------------------------------------------------
    def _on_touch(self, data: bytes) -> None:
        """A serialized Touch message (see wire)."""
        msg = common.decode(self, "touch", data)
        if msg is None:
            return
        trial, cycle = msg["trial"], msg["cycle"]
        cycles = self.touch.setdefault(trial, {})
        if cycle in cycles:
            self.repeats += 1
            self.get_logger().error(f"lockstep broken: cycle {cycle} of trial {trial} arrived "
                                    "twice")
        cycles[cycle] = msg["contact"]
        self.last_touch = time.monotonic()

    def _spin_until(self, done, timeout: float) -> bool:
        deadline = time.monotonic() + timeout
        while not done():
            if time.monotonic() > deadline:
                return False
            self.executor_.spin_once(timeout_sec=0.05)
        return True

    def _call(self, client, request, what: str):
        if not client.service_is_ready():
            raise GenerationFailed(f"the {what} service is not available")
        future = client.call_async(request)
        if not self._spin_until(future.done, self.v["service_timeout_sec"]):
            raise GenerationFailed(f"no reply from {what} within "
                                   f"{self.v['service_timeout_sec']:g} s")
        return future.result()

    def _wait_for_graph(self) -> None:
        """Block (logging now and then) until both services and the muscle commands exist."""
        said = 0.0
        while True:
            missing = [name for name, ok in (
                ("controller (set_weights service)", self.set_weights.service_is_ready()),
                ("world (reset_trials service)", self.reset_trials.service_is_ready()),
                ("controller (muscle_command publisher)",
                 self.count_publishers(common.MUSCLE_COMMAND) > 0),
                ("world (touch publisher)", self.count_publishers(common.TOUCH) > 0)) if not ok]
            if not missing:
                return
            if time.monotonic() - said > 5.0:
                self.get_logger().info("waiting for " + ", ".join(missing))
                said = time.monotonic()
            self._spin_until(lambda: False, 0.1)

    # -- one generation through the graph -------------------------------------------------------
    def _requests(self, genomes: np.ndarray, setup, seed: int, run: int, generation: int):
        """The weight swap (one network per econet, each driving its block of trials) and the
        reset that start a batch of trials exactly as the in-process engine would."""
        e = self.config.evolution
        weights = genome.decode(genomes, e.bits_per_weight, e.weight_range)
        weights_request = SetWeights.Request(
            n_envs=len(setup), weights_per_network=weights.shape[1],
            weights=common.f64(weights), noise_seed=noise_seed(seed, run, generation),
            network=self.network)
        reset_request = ResetTrials.Request(
            n_envs=len(setup), cycles=e.cycles, seed=0, object_xy=common.f64(setup.object_xy),
            body_deg=common.f64(setup.body), shoulder_deg=common.f64(setup.shoulder),
            elbow_deg=common.f64(setup.elbow))
        return weights_request, reset_request

    def test_generation(self, genomes: np.ndarray, seed: int, run: int,
                        generation: int) -> GenerationResult:
        """Like Evaluator.test_generation, with world and controller as separate nodes."""
        e = self.config.evolution
        setup = self.evaluator.trial_setups(seed, run, generation)
        weights_request, reset_request = self._requests(genomes, setup, seed, run, generation)
        contact = self._retrying(weights_request, reset_request, e.cycles, run, generation)
        return score_generation(self.config, generation, genomes,
                                TrialMeasures.from_contact(contact))

    def _retrying(self, weights_request, reset_request, cycles, run, generation, bag=None,
                  custom=None) -> np.ndarray:
        """_run_trials until it succeeds; with ``bag``, record the attempt that does (into
        bag.partial, renamed to bag once complete)."""
        attempt = 0
        while True:
            attempt += 1
            partial = bag.with_name(bag.name + ".partial") if bag else None
            try:
                if partial:
                    shutil.rmtree(partial, ignore_errors=True)
                    partial.parent.mkdir(parents=True, exist_ok=True)
                    # messages of trials before the next reset are stragglers (a retry may
                    # follow a restarted world, whose trials count from 1 again)
                    self.recorder.start(partial, custom, min_trial=self._recorded_trial + 1 if attempt == 1 else 0)
                contact = self._run_trials(weights_request, reset_request, cycles)
                if partial:
                    self._finish_recording(cycles)
                    self.recorder.stop()
                    partial.rename(bag)
                return contact
            except GenerationFailed as why:
                self.get_logger().warning(f"run {run} generation {generation}: {why}; testing "
                                          f"the {'recording' if bag else 'generation'} again "
                                          f"(attempt {attempt + 1})")
                self._wait_for_graph()
            finally:
                if self.recorder is not None:
                    self.recorder.stop()

    # -- recording --------------------------------------------------------------------------------
    def _should_record(self, generation: int) -> bool:
        every = self.v["record_every"]
        return bool(every) and (generation % every == 0
                                or generation == self.config.evolution.generations - 1)

    def record_best(self, result: GenerationResult, seed: int, run: int) -> Path | None:
        """Run the generation's best econet's trials again, recording them into a bag."""
        e = self.config.evolution
        generation = result.generation
        bag = self.record_dir / f"run-{run:02d}" / f"gen-{generation:04d}"
        if bag.exists():
            return None                         # recorded before an interruption
        best = int(result.parents[0])
        envs = np.arange(best * e.trials, (best + 1) * e.trials)
        setup = self.evaluator.trial_setups(seed, run, generation).take(envs)
        weights_request, reset_request = self._requests(result.genomes[best:best + 1], setup,
                                                        seed, run, generation)
        scored = result.measures.fitness[best]
        custom = {"econet.source": "supervisor_node", "econet.run": str(run),
                  "econet.generation": str(generation), "econet.econet": str(best),
                  "econet.controller": self.network, "econet.seed": str(seed),
                  "econet.scored_fitness": json.dumps([int(x) for x in scored]),
                  "econet.note": "the generation's best econet, its trials run once more"}
        self._retrying(weights_request, reset_request, e.cycles, run, generation, bag, custom)
        self.get_logger().info(f"run {run} generation {generation}: recorded econet {best}'s "
                               f"{len(setup)} trials into {bag}")
        return bag

    def _finish_recording(self, cycles: int) -> None:
        """After the last touch: wait until the trial's other sensor messages are recorded."""
        trial, heard = self._recorded_trial, self.recorder.heard

        def done():
            return all(heard[part, trial] >= cycles + 1
                       for part in ("retina", "proprioception", "touch")) and \
                heard["muscle_command", trial] >= cycles
        if not self._spin_until(done, self.v["service_timeout_sec"]):
            raise GenerationFailed("the recording missed messages of the trial")
        self._spin_until(lambda: False, 0.2)     # the last display pictures

    def _run_trials(self, weights_request, reset_request, cycles: int) -> np.ndarray:
        """(cycles, n_envs) contact history of one batch of trials, heard on `touch`."""
        reply = self._call(self.set_weights, weights_request, "set_weights")
        if not reply.success:
            raise Refused(f"the controller refused the weights: {reply.message}")
        self.touch.clear()
        reply = self._call(self.reset_trials, reset_request, "reset_trials")
        if not reply.success:
            raise Refused(f"the world refused the reset: {reply.message}")
        trial = reply.trial
        self._recorded_trial = trial
        for other in [t for t in self.touch if t != trial]:
            del self.touch[other]
        self.last_touch = time.monotonic()
        heard = self.touch.setdefault(trial, {})
        stall = self.v["stall_timeout_sec"]
        while len(heard) < cycles + 1:
            self.executor_.spin_once(timeout_sec=0.05)
            heard = self.touch.setdefault(trial, {})
            if self.count_publishers(common.MUSCLE_COMMAND) == 0:
                raise GenerationFailed(f"the controller vanished (nothing publishes "
                                       f"muscle_command) at cycle {len(heard) - 1} of "
                                       f"{cycles}")
            if self.count_publishers(common.TOUCH) == 0:
                raise GenerationFailed(f"the world vanished at cycle {len(heard) - 1} of "
                                       f"{cycles}")
            if time.monotonic() - self.last_touch > stall:
                raise GenerationFailed(f"no cycle for {stall:g} s after cycle "
                                       f"{len(heard) - 1} of {cycles} (controller or world "
                                       "gone?)")
        n = reset_request.n_envs
        contact = np.empty((cycles, n), dtype=bool)
        for t in range(1, cycles + 1):
            row = heard[t]
            if len(row) != n:
                raise GenerationFailed(f"touch for cycle {t} has {len(row)} environments, "
                                       f"expected {n}")
            contact[t - 1] = row != 0
        del self.touch[trial]
        return contact

    # -- the experiment -------------------------------------------------------------------------
    def evolve(self) -> int:
        v, config = self.v, self.config
        seed, runs, generations = v["seed"], v["runs"], config.evolution.generations
        if v["overwrite"]:
            for old in self.out.glob("run-*"):
                shutil.rmtree(old)
        n_weights = self.evaluator.n_weights
        self._wait_for_graph()
        self.get_logger().info(
            f"evolving {runs} run(s) x {generations} generations of "
            f"{config.evolution.population} {config.evolution.condition} econets x "
            f"{config.evolution.trials} trials x {config.evolution.cycles} cycles into "
            f"{self.out}")
        for run in range(1, runs + 1):
            store = RunStore(run_folder(self.out, run), config, seed, run, n_weights)
            try:
                generation, genomes = store.open(
                    lambda run=run: initial_genomes(config, n_weights, seed, run))
            except ConfigError as error:
                raise NodeError(str(error)) from None
            if generation:
                self.get_logger().info(f"run {run}: resuming at generation {generation}")
            while generation < generations:
                start = time.monotonic()
                result = self.test_generation(genomes, seed, run, generation)
                offspring = next_generation(config, result, seed, run)
                store.write(result, offspring)
                if self._should_record(generation):
                    self.record_best(result, seed, run)
                seconds = time.monotonic() - start
                fitness = result.fitness
                top = float(fitness[result.parents].mean())
                self.pub_progress.publish(EvolutionProgress(
                    run=run, generation=generation, generations=generations,
                    best_fitness=int(fitness.max()), top_fitness=top,
                    mean_fitness=float(fitness.mean()), seconds=seconds,
                    folder=str(store.path)))
                self.get_logger().info(
                    f"run {run} generation {generation + 1}/{generations}: best "
                    f"{int(fitness.max())}, parents' mean {top:.1f}, population mean "
                    f"{float(fitness.mean()):.1f} ({seconds:.2f} s)")
                genomes, generation = offspring, generation + 1
        self.get_logger().info(summarize(self.out, runs).replace("\n", " |"))
        # Stay a moment so that monitors, including ones that match only now, receive the last
        # progress messages (the transient-local history goes away with the process).
        self.pub_progress.wait_for_all_acked(Duration(seconds=2.0))
        self._spin_until(lambda: False, self.v["linger_sec"])
        self.pub_progress.wait_for_all_acked(Duration(seconds=2.0))
        return 0


def _body(node: SupervisorNode, executor) -> int:
    node.executor_ = executor
    try:
        return node.evolve()
    except Refused as error:
        raise NodeError(str(error)) from None


def main(args: list[str] | None = None) -> int:
    return common.run_node("supervisor_node", SupervisorNode, args, body=_body)


if __name__ == "__main__":
    sys.exit(main())

"""The supervisor node: runs the paper's evolutionary experiment through the graph.

It evolves with the one loop every command uses (``runs.run_condition`` / ``runs.evolve_into``),
handing it a GraphEvaluator that tests each generation through the world and controller nodes,
so it writes the same result folders as ``econet evolve``; a generation is written only once it
is complete, so an interrupted one is simply tested again (generations are deterministic).

Its parameters are the config's evolution settings (declared from econet_ros.config, with their
help text and ranges; defaults from the `config` file when one is given) plus the run options
below. With record_every = N > 0 it also records the best econet of generations 0, N, 2N, ...
and the last one: after the generation is written it runs that econet's trials once more (same
starts, same weights, same noise seed) with every lockstep and display topic recorded into a
rosbag2 bag, <record_dir>/run-RR/gen-GGGG (see econet_ros.recording.bags).

Subscribes  touch (econet_msgs/Touch); when recording also trial_start, retina,
            proprioception, muscle_command, joint_states, markers (raw)
Publishes   progress (econet_msgs/EvolutionProgress), one message per finished generation
Calls       set_weights (econet_msgs/SetWeights), reset_trials (econet_msgs/ResetTrials)
"""
from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np
from rclpy.duration import Duration
from rclpy.node import Node

from econet_msgs.msg import EvolutionProgress

from ..config import SETTINGS
from ..errors import ConfigError
from ..evolution import GenerationResult
from ..plugins import EXTERNAL, chosen_controller, resolve
from ..files import ensure_writable
from ..run_folders import controller_record, run_folder, writing_into
from ..runs import run_condition
from . import graph
from .graph_evaluator import GraphEvaluator
from .runner import Param, declare_parameters, default_from, node_config, run_node

# Parameters beyond the config's evolution settings.
RUN_PARAMETERS = (
    Param("seed", 1, "base random seed; a run is a pure function of it", low=0),
    Param("runs", 1, "independent runs, written to out/run-01, run-02, ...", low=1),
    Param("out", "results/graph", "output folder (same layout as econet evolve --out)"),
    Param("controller", "", "controller the controller node runs, if not the condition's "
                            "network: a registered name or module:Class (its n_params sizes "
                            "the genomes; recorded in run-NN/controller.json as econet evolve "
                            "--controller does), or 'external' for a node the supervisor does "
                            "not know (give n_weights)"),
    Param("n_weights", 0, "controller:=external only: weights per econet that the outside "
                          "controller node takes (its set_weights gets weights_per_network = "
                          "this)", low=0),
    Param("record_every", 0, "record the best econet's trials as a bag every this many "
                             "generations (and the last); 0 = never", low=0),
    Param("record_dir", "", "folder of the bags; empty = <out>/bags"),
    Param("overwrite", False, "delete out/run-* first instead of resuming them (under out's "
                              "lock, as econet evolve --overwrite)"),
    Param("stall_timeout_sec", 3.0, "test a generation again when no new cycle arrives for "
                                    "this long (a cycle the world sends again is not new)",
          low=0.01),
    Param("service_timeout_sec", 5.0, "wait this long for a service reply before retrying",
          low=0.01),
    Param("linger_sec", 1.0, "stay this long after the last generation so that late monitors "
                             "receive the final progress messages", low=0.0),
)
EVOLUTION = tuple(item for item in SETTINGS if item.section == "evolution")
PARAMETERS = (Param("config", "", "JSON config file (as econet --config); it gives the "
                                  "defaults of the evolution settings below"),
              *map(Param.of_setting, EVOLUTION), *RUN_PARAMETERS)


class SupervisorNode(Node):
    def __init__(self, controller_section: str = "", **node_options):
        """node_options go to rclpy's Node (e.g. namespace, parameter_overrides);
        controller_section: the controller named in the controller node's own section of a
        composed graph (graph_node), which counts as named here."""
        super().__init__("supervisor", **node_options)
        self.v = declare_parameters(self, PARAMETERS)
        base = node_config(self.v["config"])
        default_from(self, self.v, {item.name: getattr(base.evolution, item.name)
                                    for item in EVOLUTION})
        changes = {item.key: self.v[item.name] for item in EVOLUTION}
        self.config = base.replace(**changes)
        self.out = Path(self.v["out"])
        ensure_writable(self.out)
        condition = self.config.evolution.condition
        self.controller = chosen_controller(condition, self._named(controller_section))
        n_weights, cls = self._weight_count()
        self.plugin = controller_record(self.controller, cls, n_weights, condition)
        self.record_dir = Path(self.v["record_dir"] or self.out / "bags")
        recorder = None
        if self.v["record_every"]:
            from .topic_recorder import TopicRecorder
            recorder = TopicRecorder(self)
        # set_weights names the network it expects; an external node's own name is unknown
        expected = "" if self.controller == EXTERNAL else self.controller
        self.evaluator = GraphEvaluator(self, self.config, expected, n_weights,
                                        self.v["stall_timeout_sec"],
                                        self.v["service_timeout_sec"], recorder)
        self.pub_progress = graph.publisher(self, "progress")
        self.started = time.monotonic()

    def _named(self, section: str) -> str:
        """The controller named here or in the controller node's section (ConfigError if
        they name two)."""
        own = self.v["controller"]
        if own and section and own != section:
            raise ConfigError(f"controller:={own}, but the controller node's section says "
                              f"controller:={section}; name it once")
        return own or section

    def _weight_count(self) -> tuple[int, type | None]:
        """Weights per econet and the controller's class: the named controller's n_params, or
        n_weights and None for an external one (ConfigError if they are missing or given
        where they do not apply)."""
        n_weights = self.v["n_weights"]
        if self.controller != EXTERNAL:
            if n_weights:
                raise ConfigError(f"n_weights is for controller:=external; the "
                                  f"'{self.controller}' controller has its own weight count")
            cls = resolve(self.controller)
            return cls(1, self.config).n_params, cls
        if n_weights < 1:
            raise ConfigError("controller:=external needs n_weights:=K, the weights per econet "
                              "that the outside controller node takes (at least 1)")
        return n_weights, None

    # -- per generation -----------------------------------------------------------------------
    def on_generation(self, run: int, result: GenerationResult, offspring: np.ndarray) -> None:
        """After a generation is written: record its best econet if due, report progress."""
        if self._should_record(result.generation):
            self.record_best(result, run)
        seconds, self.started = time.monotonic() - self.started, time.monotonic()
        fitness = result.fitness
        top = float(fitness[result.parents].mean())
        generations = self.config.evolution.generations
        self.pub_progress.publish(EvolutionProgress(
            run=run, generation=result.generation, generations=generations,
            best_fitness=int(fitness.max()), top_fitness=top,
            mean_fitness=float(fitness.mean()), seconds=seconds,
            folder=str(run_folder(self.out, run))))
        self.get_logger().info(
            f"run {run} generation {result.generation + 1}/{generations}: best "
            f"{int(fitness.max())}, parents' mean {top:.1f}, population mean "
            f"{float(fitness.mean()):.1f} ({seconds:.2f} s)")

    def _should_record(self, generation: int) -> bool:
        every = self.v["record_every"]
        return bool(every) and (generation % every == 0
                                or generation == self.config.evolution.generations - 1)

    def record_best(self, result: GenerationResult, run: int) -> Path | None:
        """Run the generation's best econet's trials again, recording them into a bag."""
        seed, trials, generation = self.v["seed"], self.config.evolution.trials, \
            result.generation
        bag = run_folder(self.record_dir, run) / f"gen-{generation:04d}"
        if bag.exists():
            return None                         # recorded before an interruption
        best = int(result.parents[0])
        envs = np.arange(best * trials, (best + 1) * trials)
        setup = self.evaluator.trial_setups(seed, run, generation).take(envs)
        requests = self.evaluator.requests(result.genomes[best:best + 1], setup, seed, run,
                                           generation)
        custom = {"econet.source": "supervisor_node", "econet.run": str(run),
                  "econet.generation": str(generation), "econet.econet": str(best),
                  "econet.controller": self.controller, "econet.seed": str(seed),
                  "econet.scored_fitness": json.dumps(
                      [int(x) for x in result.measures.fitness[best]]),
                  "econet.note": "the generation's best econet, its trials run once more"}
        self.evaluator.run_batch(*requests, where=f"run {run} generation {generation}",
                                 bag=bag, custom=custom)
        self.get_logger().info(f"run {run} generation {generation}: recorded econet {best}'s "
                               f"{len(setup)} trials into {bag}")
        return bag

    # -- the experiment -------------------------------------------------------------------------
    def evolve(self) -> int:
        v, e = self.v, self.config.evolution
        with writing_into(self.out, overwrite=v["overwrite"]):
            self.evaluator.wait_for_graph()
            self.get_logger().info(
                f"evolving {v['runs']} run(s) x {e.generations} generations of {e.population} "
                f"{e.condition} econets x {e.trials} trials x {e.cycles} cycles into {self.out}")
            self.started = time.monotonic()
            summary = run_condition(
                self.config, v["runs"], v["seed"], self.out, progress=False,
                evaluator=self.evaluator, on_generation=self.on_generation, plugin=self.plugin)
        self.get_logger().info(summary.replace("\n", " |"))
        # Stay a moment so that monitors, including ones that match only now, receive the last
        # progress messages (the transient-local history goes away with the process).
        self.pub_progress.wait_for_all_acked(Duration(seconds=2.0))
        self.evaluator.spin_until(lambda: False, v["linger_sec"])
        self.pub_progress.wait_for_all_acked(Duration(seconds=2.0))
        return 0


def evolve_with(node: SupervisorNode, executor) -> int:
    """The supervisor's run: evolve, spinning ``executor`` whenever it waits for a reply or a
    message (in a composed graph that executor serves the world and controller too)."""
    node.evaluator.executor = executor
    return node.evolve()


def main(args: list[str] | None = None) -> int:
    return run_node("supervisor_node", SupervisorNode, args, body=evolve_with,
                    parameters=PARAMETERS, doc=__doc__)


if __name__ == "__main__":
    sys.exit(main())

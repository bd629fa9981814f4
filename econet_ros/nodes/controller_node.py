"""The controller node: a batch of controllers (econet_ros.controllers: the paper's networks,
random movement, the hand-written reacher, or any plug-in by name or module:Class) answering
each cycle's sensors with muscle commands.

Subscribes  retina, proprioception, touch (econet_msgs), each taken only from one publisher: the
            world it pairs with (graph.Partner)
Publishes   muscle_command (econet_msgs/MuscleCommand), once per complete non-final cycle
Serves      set_weights (econet_msgs/SetWeights)
"""
from __future__ import annotations

import sys

import numpy as np
from rclpy.node import Node
from rclpy.parameter import Parameter

from ..config import Config
from ..errors import ConfigError, PluginError
from .lockstep_wire import CommandMessage, SensorMessages
from ..plugins import chosen_controller, resolve
from ..topics import COMMAND, MAX_ENVS, SENSORS, observation_from_fields, sensor_problem
from ..world import World
from . import graph
from .runner import Param, declare_parameters, default_from, node_config, run_node

MAX_PENDING = 16     # incomplete cycles kept while waiting for their other sensor messages


PARAMETERS = (
    Param("controller", "", "a registered name (normal, three-layer, random, reacher, or a "
                            "plug-in's entry point) or module:Class; empty = the condition's "
                            "network (as the supervisor's controller)"),
    Param("condition", "", "the paper condition whose network runs when controller is empty "
                           "(give it the supervisor's condition); empty = the config's"),
    Param("config", "", "JSON config file (as econet --config); its model and network sections "
                        "size the network; empty = defaults"),
    Param("n_envs", 1, "environments at start-up (set_weights may change it)", low=1,
          high=MAX_ENVS),
    Param("max_abs_weight", Config().evolution.weight_range,
          "set_weights refuses weights beyond +-this value (default: the config's "
          "weight_range)", low=0.0),
)


class ControllerNode(Node):
    def __init__(self, **node_options):
        """node_options go to rclpy's Node (e.g. cli_args, as graph_node gives them)."""
        super().__init__("controller", **node_options)
        v = declare_parameters(self, PARAMETERS)
        self.config = node_config(v["config"])
        default_from(self, v, {"max_abs_weight": self.config.evolution.weight_range,
                               "condition": self.config.evolution.condition})
        self.named = v["controller"]        # "" when none was named (graph_node asks)
        self.max_abs, n_envs = v["max_abs_weight"], v["n_envs"]
        self._start(chosen_controller(v["condition"], self.named), n_envs)
        self.pending: dict[tuple[int, int], dict] = {}   # (trial, cycle) -> decoded parts
        self.command = CommandMessage(n_envs)
        # The last cycle answered and the bytes sent for it: a cycle the world sends again
        # (world_node.RESEND_SEC) is answered with the same command, never computed twice, so
        # that a controller with a state (random movement's generator) does not move on.
        self.answered: tuple[tuple[int, int], bytes] | None = None

        self.pub = graph.publisher(self, COMMAND)
        self.refusals = graph.RateLimitedLog(self)
        self.world = {part: graph.Partner(self, part, self.refusals) for part in SENSORS}
        for part in SENSORS:
            graph.subscription(self, part, lambda data, gid, part=part: self._on_part(
                part, data, gid), raw=True, with_publisher=True)
        graph.service(self, "set_weights", self._on_set_weights)
        self._say_ready()

    def _start(self, name: str, n_envs: int) -> None:
        """Run the controller ``name`` (its kernels compiled), or ConfigError in one line."""
        try:
            self.cls = resolve(name)
            self.controller = self.cls(n_envs, self.config)
            self._compile_kernels()
        except PluginError:
            raise
        except Exception as error:  # noqa: BLE001 - a plug-in that fails: one line
            raise ConfigError(f"controller '{name}' failed to start: "
                              f"{type(error).__name__}: {error}") from None
        self.controller_name = name

    def follow(self, name: str) -> None:
        """Run the controller the graph's supervisor decided on (graph_node: the controller
        named in either node's section, else the supervisor's condition's network)."""
        if name != self.controller_name:
            self._start(name, self.controller.n_envs)
            self.set_parameters([Parameter("controller", value=name)])
            self._say_ready()

    def _say_ready(self) -> None:
        self.get_logger().info(f"controller ready: {self.controller_name} ({self.cls.__module__}:"
                               f"{self.cls.__qualname__}), "
                               f"{self.controller.n_params} weights per environment")

    def _compile_kernels(self) -> None:
        """Compile (or load) the network's kernel now, not in the first timed cycle, for sensors
        as they arrive (read-only arrays), so that "ready" means ready."""
        world = World(1, self.config.model)
        wire = SensorMessages(1, self.config.model.visual_units)
        wire.write(world, 0, False)
        parts = {part: graph.decode(self, part, data) for part, data in wire.encoded().items()}
        CommandMessage(1).encode(0, 0, self.cls(1, self.config).act(
            observation_from_fields(parts)))

    # -- weights ------------------------------------------------------------------------------
    def _on_set_weights(self, request, response):
        problem = self._check(request)
        if problem:
            response.success, response.message = False, problem
            self.refusals.error(f"set_weights refused: {problem}")
            return response
        n, k = int(request.n_envs), int(request.weights_per_network)
        weights = graph.as_f64(request.weights).reshape(-1, k) if k else None
        controller = self.controller
        if controller.n_envs != n:
            controller = self.cls(n, self.config)
        try:
            controller.load(weights if k else np.zeros((n, 0)), int(request.noise_seed))
        except ValueError as error:
            response.success, response.message = False, f"the controller refused: {error}"
            return response
        self.controller, self.answered = controller, None
        response.success = True
        response.message = f"loaded weights for {n} environment(s) x {k}"
        return response

    def _check(self, request) -> str | None:
        """Why a weight swap cannot be applied (None if it can); nothing is changed here."""
        # SetWeights names the controller it expects in its field `network`
        if request.network and request.network != self.controller_name:
            return (f"this controller runs the '{self.controller_name}' network, the request "
                    f"expects '{request.network}'")
        expected = self.controller.n_params
        if request.weights_per_network != expected:
            return (f"weights_per_network is {request.weights_per_network}, the "
                    f"{self.controller_name} network has {expected} weights")
        if not 1 <= request.n_envs <= MAX_ENVS:
            return f"n_envs must be between 1 and {MAX_ENVS}, got {request.n_envs}"
        if expected == 0:       # nothing to load (e.g. the reacher): only the batch size
            return None if not len(request.weights) else (
                f"the {self.controller_name} controller takes no weights, got "
                f"{len(request.weights)}")
        networks, left = divmod(len(request.weights), max(expected, 1))
        if left or not networks or request.n_envs % networks:
            return (f"got {len(request.weights)} weights: expected n_networks x "
                    f"{expected} with n_networks dividing n_envs = {request.n_envs}")
        weights = graph.as_f64(request.weights)
        if not np.all(np.isfinite(weights)):
            return "weights contain NaN or infinite values"
        if np.any(np.abs(weights) > self.max_abs):
            worst = float(weights[np.argmax(np.abs(weights))])
            return f"weight {worst:g} is outside the allowed range +-{self.max_abs:g}"
        return None

    # -- sensors -> command -------------------------------------------------------------------
    def _on_part(self, part: str, data: bytes, publisher: bytes) -> None:
        """A serialized sensor message (see wire) from the partner world; the command goes out
        once a cycle's three messages are in. A message that cannot be a cycle of this
        controller's batch is refused before anything is computed from it."""
        if not self.world[part].accepts(publisher):
            return
        msg = graph.decode(self, part, data)
        if msg is None or msg["final"]:
            return                      # a trial's last cycle: the world takes no command
        problem = sensor_problem(part, msg, self.controller.n_envs,
                                 self.config.model.visual_units)
        if problem:
            self.refusals.error(f"ignored trial {msg['trial']} cycle {msg['cycle']}: {problem}")
            return
        key = (msg["trial"], msg["cycle"])
        parts = self.pending.get(key)
        if parts is None:
            if len(self.pending) >= MAX_PENDING:
                self.pending.pop(next(iter(self.pending)))
            parts = self.pending[key] = {}
        parts[part] = msg
        if len(parts) == len(SENSORS):
            # Everything received before this cycle is stale or incomplete for good.
            for old in list(self.pending):
                del self.pending[old]
                if old == key:
                    break
            self._act(parts)

    def _act(self, parts: dict) -> None:
        """The network's outputs, written into the reused command message (lockstep_wire); a
        cycle answered already gets the same bytes again."""
        retina = parts["retina"]
        key = (retina["trial"], retina["cycle"])
        if self.answered is None or self.answered[0] != key:
            motor = self.controller.act(observation_from_fields(parts))
            if self.command.n_envs != len(motor):
                self.command = CommandMessage(len(motor))
            self.answered = key, self.command.encode(*key, motor)
        graph.send(self, self.pub, self.answered[1])


def main(args: list[str] | None = None) -> int:
    return run_node("controller_node", ControllerNode, args, parameters=PARAMETERS,
                    doc=__doc__)


if __name__ == "__main__":
    sys.exit(main())

"""The controller node: a batch of econet networks (econet_ros.controllers) answering each
cycle's sensors with muscle commands.

Subscribes  retina, proprioception, touch (econet_msgs)
Publishes   muscle_command (econet_msgs/MuscleCommand), once per complete non-final cycle
Serves      set_weights (econet_msgs/SetWeights)
"""
from __future__ import annotations

import sys

import numpy as np
from rclpy.node import Node

from econet_msgs.msg import MuscleCommand, Proprioception, Retina, Touch
from econet_msgs.srv import SetWeights

from ..config import CONDITIONS
from ..controllers import make_controller
from ..world import N_PROPRIO, Observation, World
from . import common
from .common import NodeError

PARTS = ("retina", "proprioception", "touch")
MAX_PENDING = 16     # incomplete cycles kept while waiting for their other sensor messages


class ControllerNode(Node):
    def __init__(self):
        super().__init__("controller")
        self.network = common.declare(self, "network", "normal",
                                      "network: normal (four-layer), three-layer, random")
        config_path = common.declare(self, "config", "",
                                     "JSON config file (as econet --config); its model and "
                                     "network sections size the network; empty = defaults")
        n_envs = common.declare(self, "n_envs", 1,
                                "environments at start-up (set_weights may change it)")
        self.config = common.node_config(config_path)
        self.max_abs = common.declare(self, "max_abs_weight",
                                      float(self.config.evolution.weight_range),
                                      "set_weights refuses weights beyond +-this value")
        if self.network not in CONDITIONS:
            raise NodeError(f"network must be one of {', '.join(CONDITIONS)}, "
                            f"got '{self.network}'")
        if n_envs < 1:
            raise NodeError(f"n_envs must be at least 1, got {n_envs}")
        self.controller = make_controller(self.network, n_envs, self.config)
        # compile (or load) the network's kernel now, not in the first timed cycle
        make_controller(self.network, 1, self.config).act(World(1, self.config.model).observe())
        self.pending: dict[tuple[int, int], dict] = {}
        self.answered = (-1, -1)

        qos = common.LOCKSTEP_QOS
        self.pub = self.create_publisher(MuscleCommand, common.MUSCLE_COMMAND, qos)
        self.create_subscription(Retina, common.RETINA,
                                 lambda msg: self._on_part("retina", msg), qos)
        self.create_subscription(Proprioception, common.PROPRIOCEPTION,
                                 lambda msg: self._on_part("proprioception", msg), qos)
        self.create_subscription(Touch, common.TOUCH, lambda msg: self._on_part("touch", msg),
                                 qos)
        self.create_service(SetWeights, common.SET_WEIGHTS, self._on_set_weights)
        self.get_logger().info(f"controller ready: {self.network} network, "
                               f"{self.controller.n_params} weights per environment")

    # -- weights ------------------------------------------------------------------------------
    def _on_set_weights(self, request: SetWeights.Request, response: SetWeights.Response):
        problem = self._check(request)
        if problem:
            response.success, response.message = False, problem
            self.get_logger().error(f"set_weights refused: {problem}")
            return response
        n, k = int(request.n_envs), int(request.weights_per_network)
        weights = common.as_f64(request.weights).reshape(-1, k)
        controller = self.controller
        if controller.n_envs != n:
            controller = make_controller(self.network, n, self.config)
        controller.load(weights, int(request.noise_seed))
        self.controller = controller
        response.success = True
        response.message = f"loaded weights for {n} environment(s) x {k}"
        return response

    def _check(self, request: SetWeights.Request) -> str | None:
        """Why a weight swap cannot be applied (None if it can); nothing is changed here."""
        if request.network and request.network != self.network:
            return (f"this controller runs the '{self.network}' network, the request expects "
                    f"'{request.network}'")
        expected = self.controller.n_params
        if request.weights_per_network != expected:
            return (f"weights_per_network is {request.weights_per_network}, the "
                    f"{self.network} network has {expected} weights")
        if request.n_envs < 1:
            return "n_envs must be at least 1"
        networks, left = divmod(len(request.weights), max(expected, 1))
        if left or not networks or request.n_envs % networks:
            return (f"got {len(request.weights)} weights: expected n_networks x "
                    f"{expected} with n_networks dividing n_envs = {request.n_envs}")
        weights = common.as_f64(request.weights)
        if not np.all(np.isfinite(weights)):
            return "weights contain NaN or infinite values"
        if np.any(np.abs(weights) > self.max_abs):
            worst = float(weights[np.argmax(np.abs(weights))])
            return f"weight {worst:g} is outside the allowed range +-{self.max_abs:g}"
        return None

    # -- sensors -> command -------------------------------------------------------------------
    def _on_part(self, part: str, msg) -> None:
        key = (msg.trial, msg.cycle)
        parts = self.pending.get(key)
        if parts is None:
            if len(self.pending) >= MAX_PENDING:
                self.pending.pop(next(iter(self.pending)))
            parts = self.pending[key] = {}
        parts[part] = msg
        if len(parts) == len(PARTS):
            # Everything received before this cycle is stale or incomplete for good.
            for old in list(self.pending):
                del self.pending[old]
                if old == key:
                    break
            self._act(parts)

    def _act(self, parts: dict) -> None:
        retina, proprio, touch = (parts[p] for p in PARTS)
        if retina.final:
            return                      # the trial is over: the world takes no command
        n = retina.n_envs
        if n != self.controller.n_envs:
            self.get_logger().warning(
                f"sensors for {n} environment(s), but the controller has "
                f"{self.controller.n_envs}: call set_weights with n_envs={n}",
                throttle_duration_sec=5.0)
            return
        vision = common.as_f64(retina.activation).reshape(n, retina.units_per_env)
        stretch = common.as_f64(proprio.stretch).reshape(n, N_PROPRIO)
        contact = common.as_u8(touch.contact).astype(np.float64)
        fixated = common.as_u8(retina.fixated).astype(bool)
        motor = self.controller.act(Observation(retina.cycle, vision, stretch, contact,
                                                fixated))
        self.pub.publish(MuscleCommand(trial=retina.trial, cycle=retina.cycle, n_envs=n,
                                       activation=common.f64(motor)))


def main(args: list[str] | None = None) -> int:
    return common.run_node("controller_node", ControllerNode, args)


if __name__ == "__main__":
    sys.exit(main())

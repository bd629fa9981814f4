"""A controller *node* from outside econet_ros (test fixture), written as a user of the graph
would from docs/controllers.md alone: rclpy, econet_msgs and numpy, no econet_ros import.

One logistic layer from the 13 inputs (8 visual units, 4 stretch values, touch) to the 5
muscles, 65 weights per network: the same arithmetic as econet_plugin_example's
LinearController, so a run evolved through this node can be compared with one evolved in
process.

    python -m econet_outside_node [--ros-args -r __ns:=/lab]
"""
import array
import sys

import numpy as np
import rclpy
from rclpy.node import Node
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy

from econet_msgs.msg import MuscleCommand, Proprioception, Retina, Touch
from econet_msgs.srv import SetWeights

N_INPUTS, N_MUSCLES = 13, 5
N_WEIGHTS = N_INPUTS * N_MUSCLES
LOCKSTEP = QoSProfile(history=HistoryPolicy.KEEP_ALL, reliability=ReliabilityPolicy.RELIABLE)


class OutsideController(Node):
    def __init__(self):
        super().__init__("outside_controller")
        self.weights = np.zeros((1, N_WEIGHTS))
        self.n_envs = 1
        self.cycles = {}            # (trial, cycle) -> {topic: message}
        self.pub = self.create_publisher(MuscleCommand, "muscle_command", LOCKSTEP)
        for topic, kind in (("retina", Retina), ("proprioception", Proprioception),
                            ("touch", Touch)):
            self.create_subscription(kind, topic, lambda m, t=topic: self.on_sensor(t, m),
                                     LOCKSTEP)
        self.create_service(SetWeights, "set_weights", self.on_set_weights)

    def on_set_weights(self, request, response):
        weights = np.frombuffer(request.weights, dtype=np.float64)
        k = request.weights_per_network
        if k != N_WEIGHTS or not len(weights) or len(weights) % k or \
                request.n_envs % (len(weights) // k):
            response.success = False
            response.message = f"this controller takes n_networks x {N_WEIGHTS} weights"
            return response
        self.weights, self.n_envs = weights.reshape(-1, k).copy(), request.n_envs
        response.success, response.message = True, "ok"
        return response

    def on_sensor(self, topic, msg):
        parts = self.cycles.setdefault((msg.trial, msg.cycle), {})
        parts[topic] = msg
        if len(parts) < 3:
            return
        del self.cycles[(msg.trial, msg.cycle)]
        retina = parts["retina"]
        if retina.final or retina.n_envs != self.n_envs:
            return
        n = self.n_envs
        inputs = np.concatenate([
            np.frombuffer(retina.activation, np.float64).reshape(n, -1),
            np.frombuffer(parts["proprioception"].stretch, np.float64).reshape(n, 4),
            np.frombuffer(parts["touch"].contact, np.uint8).astype(np.float64)[:, None]],
            axis=1)
        w = np.repeat(self.weights, n // len(self.weights), axis=0).reshape(n, N_MUSCLES,
                                                                           N_INPUTS)
        motor = 1.0 / (1.0 + np.exp(-np.einsum("noi,ni->no", w, inputs)))
        self.pub.publish(MuscleCommand(trial=msg.trial, cycle=msg.cycle, n_envs=n,
                                       activation=array.array("d", motor.tobytes())))


def main() -> int:
    rclpy.init()
    node = OutsideController()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, rclpy.executors.ExternalShutdownException):
        pass
    return 0


if __name__ == "__main__":
    sys.exit(main())

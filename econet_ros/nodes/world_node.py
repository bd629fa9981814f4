"""The world node: owns a batch of econet environments (econet_ros.world.World) and runs them
in lockstep with a controller, or free-running at a fixed rate for demonstrations.

Publishes   trial_start (econet_msgs/TrialStart) at every reset; retina (econet_msgs/Retina),
            proprioception (econet_msgs/Proprioception) and touch (econet_msgs/Touch) once per
            cycle; joint_states (sensor_msgs/JointState) and markers
            (visualization_msgs/MarkerArray) for one display environment, throttled, built by
            recording/display.py and sent as bytes; /tf_static (tf2_msgs/TFMessage) once,
            where tf2_msgs is installed
Subscribes  muscle_command (econet_msgs/MuscleCommand), taken only from one publisher: the
            controller it pairs with (graph.Partner)
Serves      reset_trials (econet_msgs/ResetTrials)
"""
from __future__ import annotations

import sys
import time

import numpy as np
from rclpy.node import Node

from econet_msgs.msg import TrialStart

from ..errors import ConfigError, SetupError
from .lockstep_wire import CommandMessage, SensorMessages
from ..recording import display
from ..topics import COMMAND, FRAME, MAX_ENVS, SENSORS, trial_start_fields
from ..world import N_MOTOR, Observation, TrialSetup, World, check_setup, sample_setups
from . import graph
from .runner import Param, declare_parameters, node_config, run_node

MODES = ("lockstep", "free")
NEUTRAL = np.array([0.5, 0.0, 0.0, 0.0, 0.0])   # eye still, no muscle pulls
# Lockstep: a cycle whose command has not come for this long has its sensor messages sent
# again, so a controller that matched after they went out (DDS discovery right after start)
# or restarted mid-trial picks the trial up instead of both waiting for ever.
RESEND_SEC = 1.0

PARAMETERS = (
    Param("n_envs", 1, "environments at start-up (a reset may change it)", low=1,
          high=MAX_ENVS),
    Param("config", "", "JSON config file (as econet --config); only its model section is "
                        "used; empty = the paper's defaults"),
    Param("mode", "lockstep", "lockstep: advance one cycle per matching muscle command; free: "
                              "advance at rate_hz with the newest command", choices=MODES),
    Param("rate_hz", 10.0, "cycles per second in free mode", low=0.01, high=10000.0),
    Param("trial_cycles", 100, "free mode: start a new random trial after this many cycles "
                               "(0 = never)", low=0),
    Param("seed", 0, "seed of the trials free mode draws (trial k uses seed + k)", low=0),
    Param("display_env", 0, "environment shown on joint_states and markers (below n_envs)",
          low=0),
    Param("display_rate_hz", 20.0, "most joint_states/markers pictures per second: in free "
                                   "mode every k-th cycle where it divides rate_hz, else by "
                                   "the wall clock (0 = every cycle, costly in lockstep)",
          low=0.0),
    Param("frame_id", FRAME, "frame of the pictures: the agent at its origin, x right, y up, "
                             "one workspace unit = 1 m; /tf_static puts it at the origin of "
                             "map"),
)


class WorldNode(Node):
    def __init__(self, **node_options):
        """node_options go to rclpy's Node (e.g. cli_args, as graph_node gives them)."""
        super().__init__("world", **node_options)
        v = declare_parameters(self, PARAMETERS)
        self.refusals = graph.RateLimitedLog(self)
        n_envs, rate, display_rate = v["n_envs"], v["rate_hz"], v["display_rate_hz"]
        self.mode, self.free_cycles, self.seed = v["mode"], v["trial_cycles"], v["seed"]
        self.display_env, self.frame_id = v["display_env"], v["frame_id"]
        if self.display_env >= n_envs:
            raise ConfigError(f"display_env must be below n_envs ({n_envs}), got "
                              f"{self.display_env}")
        self.model = node_config(v["config"]).model
        self.pictures = display.PictureClock(display_rate, rate if self.mode == "free" else None)

        self._compile_kernels()
        self.world = World(n_envs, self.model)
        self.wire = SensorMessages(n_envs, self.model.visual_units)
        # and load the picture's message types (a fifth of a second), not in the first cycle
        display.picture(self.world, 0, False, False, self.frame_id, 0)
        self.trial = 0
        self.limit = 0          # trial length; 0 = unlimited
        self.started = False    # lockstep: no trial until the first reset
        self.latest = None      # free mode: newest command

        self.sensor_pubs = {part: graph.publisher(self, part) for part in SENSORS}
        self.pub_start = graph.publisher(self, "trial_start")
        self.pub_joints = graph.publisher(self, "joint_states")
        self.pub_markers = graph.publisher(self, "markers")
        self._publish_frame()
        self.controller = graph.Partner(self, COMMAND, self.refusals)
        graph.subscription(self, COMMAND, self._on_command, raw=True, with_publisher=True)
        graph.service(self, "reset_trials", self._on_reset)

        self.unanswered: tuple[dict, float] | None = None   # lockstep: sensors sent, when
        if self.mode == "free":
            self._new_free_trial()
            self.create_timer(1.0 / rate, self._on_tick)
        else:
            self.create_timer(RESEND_SEC / 4, self._resend_if_unanswered)
        self.get_logger().info(f"world ready: {n_envs} environment(s), {self.mode} mode")

    def _compile_kernels(self) -> None:
        """Compile (or load) the kernels of a cycle now, not in the first timed one, for
        commands as they arrive (read-only arrays), so that "ready" means ready."""
        world, wire = World(1, self.model), SensorMessages(1, self.model.visual_units)
        wire.write(world, 0, False)
        command = graph.decode(self, COMMAND, CommandMessage(1).encode(0, 0, NEUTRAL[None, :]))
        wire.step(world, self._motor(command, n_envs=1), 0, False)

    def _publish_frame(self) -> None:
        """/tf_static: the frame of the pictures at the origin of `map` (RViz's default fixed
        frame). tf2_msgs is not among the PyPI wheels; without it the bags and the viewer still
        carry the frame."""
        static = graph.tf_static_publisher(self)
        if static is None:
            self.get_logger().info("tf2_msgs is not installed: no /tf_static (bags and the "
                                   "viewer carry the frame themselves)")
            return
        self.pub_static = static
        static.publish(display.tf_static(self.frame_id, self.get_clock().now().nanoseconds))

    # -- trials -----------------------------------------------------------------------------
    def _start(self, setup: TrialSetup, cycles: int) -> None:
        if len(setup) != self.world.n_envs:
            self.world = World(len(setup), self.model)
            self.wire = SensorMessages(len(setup), self.model.visual_units)
        self.world.reset(setup)
        self.pictures.restart()
        self.trial += 1
        self.limit = cycles
        self.started = True
        self.pub_start.publish(TrialStart(**graph.typed(trial_start_fields(
            self.trial, cycles, self.mode == "lockstep", setup, self.model))))
        final = self._final(0)
        self.wire.write(self.world, self.trial, final)
        self._publish(self.world.observe(), final)

    def _new_free_trial(self) -> None:
        rng = np.random.default_rng(self.seed + self.trial + 1)
        self._start(sample_setups(rng, self.world.n_envs, self.model), self.free_cycles)

    def _on_reset(self, request, response):
        try:
            setup = self._setup_from(request)
        except SetupError as error:
            response.success = False
            response.message = str(error)
            self.refusals.error(f"reset refused: {error}")
        else:
            self._start(setup, int(request.cycles))
            response.success = True
            response.message = f"trial {self.trial} started in {len(setup)} environment(s)"
        response.trial = self.trial
        response.n_envs = self.world.n_envs
        return response

    def _setup_from(self, request) -> TrialSetup:
        """The trial starts a request describes (SetupError, one line, if they cannot work):
        each array given in full, or left empty to be drawn from the request's seed."""
        n = int(request.n_envs) or self.world.n_envs
        if n > MAX_ENVS:
            raise SetupError(f"n_envs is {n}; a world holds at most {MAX_ENVS} environments")
        drawn = sample_setups(np.random.default_rng(request.seed), n, self.model)
        parts = {}
        for name, width in (("object_xy", 2), ("body_deg", 1), ("shoulder_deg", 1),
                            ("elbow_deg", 1)):
            values = graph.as_f64(getattr(request, name))
            if len(values) == 0:
                continue
            if len(values) != n * width:
                raise SetupError(f"{name} has {len(values)} values, expected {n * width} "
                                 f"({n} environment(s) x {width}) or none")
            parts[name] = values.reshape(n, 2) if width == 2 else values.copy()
        setup = TrialSetup(parts.get("object_xy", drawn.object_xy),
                           parts.get("body_deg", drawn.body),
                           parts.get("shoulder_deg", drawn.shoulder),
                           parts.get("elbow_deg", drawn.elbow))
        check_setup(setup, self.model)
        return setup

    # -- commands ---------------------------------------------------------------------------
    def _on_command(self, data: bytes, publisher: bytes) -> None:
        """A serialized MuscleCommand (see wire: read in place, no message object), applied
        only if it comes from the partner controller."""
        if not self.controller.accepts(publisher):
            return
        msg = graph.decode(self, COMMAND, data)
        if msg is None:
            return
        if self.mode == "free":
            motor = self._motor(msg)
            if motor is not None and np.all(np.isfinite(motor)):
                self.latest = motor
            elif motor is not None:
                self._not_finite()
            return
        late = self._out_of_step(msg)
        if late:
            self.refusals.error(f"rejected muscle command for trial {msg['trial']} cycle "
                                f"{msg['cycle']}: {late}")
            return
        motor = self._motor(msg)
        if motor is None:
            return
        self._step(motor)

    def _step(self, motor: np.ndarray) -> None:
        """One cycle: the world moves, senses and writes the sensor messages in one kernel
        launch (which checks that every command value is finite); they go out."""
        final = self._final(self.world.cycle + 1)
        try:
            obs = self.wire.step(self.world, motor, self.trial, final)
        except ValueError:
            self._not_finite()
            return
        self._publish(obs, final)

    def _final(self, cycle: int) -> bool:
        """Whether ``cycle`` is the trial's last."""
        return bool(self.limit and cycle >= self.limit)

    def _out_of_step(self, msg: dict) -> str | None:
        """Why a lockstep command is not the one the world waits for (None if it is)."""
        if not self.started:
            return "no trial yet (call reset_trials)"
        if msg["trial"] != self.trial or msg["cycle"] != self.world.cycle:
            return f"the world is at trial {self.trial} cycle {self.world.cycle}"
        if self.limit and self.world.cycle >= self.limit:
            return "the trial is over (reset_trials starts the next)"
        return None

    def _not_finite(self) -> None:
        self.refusals.error("rejected muscle command: it contains NaN or infinite values")

    def _motor(self, msg: dict, n_envs: int | None = None) -> np.ndarray | None:
        """The command's (n, 5) outputs, or None (logged) if their number is wrong."""
        n = self.world.n_envs if n_envs is None else n_envs
        motor = msg["activation"]
        if msg["n_envs"] != n or len(motor) != n * N_MOTOR:
            self.refusals.error(f"rejected muscle command: {len(motor)} values for "
                                f"n_envs={msg['n_envs']}, the world has {n} environment(s) x "
                                f"{N_MOTOR} muscles = {n * N_MOTOR} values")
            return None
        return motor.reshape(n, N_MOTOR)

    def _on_tick(self) -> None:
        if self.free_cycles and self.world.cycle >= self.free_cycles:
            self._new_free_trial()
            return
        motor = self.latest
        if motor is None or motor.shape[0] != self.world.n_envs:
            motor = np.tile(NEUTRAL, (self.world.n_envs, 1))
        self._step(motor)

    # -- output -----------------------------------------------------------------------------
    def _publish(self, obs: Observation, final: bool) -> None:
        """The cycle's sensor messages, as the world's kernel wrote them (lockstep_wire)."""
        sensors = self.wire.encoded()
        for part, data in sensors.items():
            graph.send(self, self.sensor_pubs[part], data)
        now = time.monotonic()
        if self.mode == "lockstep":
            self.unanswered = None if final else (sensors, now)
        if self.pictures.due(obs.cycle, final, now):
            self._publish_display(obs)

    def _resend_if_unanswered(self) -> None:
        """The current cycle's sensor messages again, byte for byte, once no command has come
        for RESEND_SEC (readers take a repeat as the same cycle)."""
        if self.unanswered is None or time.monotonic() - self.unanswered[1] < RESEND_SEC:
            return
        sensors = self.unanswered[0]
        for part, data in sensors.items():
            graph.send(self, self.sensor_pubs[part], data)
        self.unanswered = (sensors, time.monotonic())
        self.refusals.warning(f"no command for trial {self.trial} cycle {self.world.cycle} in "
                              f"{RESEND_SEC:g} s: sent its sensors again (a controller that "
                              "matched late or restarted picks it up)", kind="resend")

    def _publish_display(self, obs: Observation) -> None:
        """The display environment's picture (recording/display.py), published as bytes."""
        i = min(self.display_env, self.world.n_envs - 1)
        pictures = display.picture(self.world, i, bool(obs.touch[i] > 0.5),
                                   bool(obs.fixated[i]), self.frame_id,
                                   self.get_clock().now().nanoseconds)
        graph.send(self, self.pub_joints, pictures["joint_states"])
        graph.send(self, self.pub_markers, pictures["markers"])


def main(args: list[str] | None = None) -> int:
    return run_node("world_node", WorldNode, args, parameters=PARAMETERS, doc=__doc__)


if __name__ == "__main__":
    sys.exit(main())

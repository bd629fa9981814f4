"""The nodes as a ROS user starts and stops them, each as its own process: --help, parameters as
typed on the command line (an integer for a float is fine; anything else that cannot work is
one line and exit 2), the ranges `ros2 param describe` would show, and SIGINT / SIGTERM to any
node, alone or together, while the others keep publishing: exit 0 and no traceback."""
import os
import signal
import subprocess
import sys

import pytest

from graph_helpers import REPO, ros_session, spin_until

pytestmark = pytest.mark.ros       # every test here starts ROS nodes

NODES = ("world", "controller", "supervisor", "recorder", "viewer")


def run_node(node: str, *params: str, extra=()):
    args = [sys.executable, "-m", f"econet_ros.nodes.{node}_node", *extra]
    if params:
        args += ["--ros-args", *[x for p in params for x in ("-p", p)]]
    return subprocess.run(args, cwd=REPO, capture_output=True, text=True, timeout=120,
                          stdin=subprocess.DEVNULL)


@pytest.mark.parametrize("node", NODES)
def test_help_lists_parameters_and_starts_nothing(node, tmp_path):
    bag = tmp_path / "never"
    proc = run_node(node, f"out:={bag}", extra=["--help"])
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.startswith(f"usage: {node}_node [--ros-args -p NAME:=VALUE ...]")
    assert "parameters:" in proc.stdout and proc.stderr == ""
    assert not bag.exists()                     # the recorder did not start recording
    if node == "world":
        assert "rate_hz (double, default 10.0, 0.01 to 10000)" in proc.stdout
        assert "trial_cycles (integer, default 100, at least 0)" in proc.stdout
    if node == "supervisor":
        assert "condition (string, default 'normal', one of normal, three-layer, random)" \
            in proc.stdout


@pytest.mark.parametrize("command", [["scripts/node", "recorder"],
                                     ["install/econet_ros/lib/econet_ros/recorder_node"]])
def test_help_through_scripts_node_and_the_installed_executable(command):
    proc = subprocess.run([str(REPO / command[0]), *command[1:], "--help"], cwd=REPO,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert "topics (string, default 'trial_start,retina," in proc.stdout


@pytest.mark.parametrize("node, param, message", [
    ("world", "rate_hz:=fast", "rate_hz must be a finite number, got 'fast'"),
    ("world", "trial_cycles:=-5", "trial_cycles must be at least 0, got -5"),
    ("world", "display_env:=4", "display_env must be below n_envs (1), got 4"),
    ("world", "mode:=slow", "mode must be one of lockstep, free, got 'slow'"),
    ("world", "rate:=20", "unknown parameter(s) rate (see --help)"),
    ("controller", "n_envs:=0", "n_envs must be between 1 and 100000, got 0"),
    ("controller", "max_abs_weight:=true", "max_abs_weight must be a finite number, got True"),
    ("supervisor", "population:=2.5", "population must be a whole number, got 2.5"),
    ("supervisor", "overwrite:=3", "overwrite must be true or false, got 3"),
    ("recorder", "topic:=retina", "unknown parameter(s) topic (see --help)"),
])
def test_bad_parameters_are_one_line_errors(node, param, message):
    proc = run_node(node, param)
    assert proc.returncode == 2
    assert proc.stderr.strip().splitlines() == [f"{node}_node: error: {message}"]


@pytest.fixture(scope="module")
def ros(tmp_path_factory):
    yield from ros_session(tmp_path_factory, 30 + os.getpid() % 15, "lifecycle")


def test_integer_for_a_float_and_ranges_in_the_descriptors(ros):
    """`rate_hz:=20` (an integer) starts the world as the README shows; its descriptors carry
    the ranges (what `ros2 param describe /world rate_hz` prints)."""
    rclpy, executor, procs = ros
    from rcl_interfaces.msg import ParameterType
    from rclpy.parameter_client import AsyncParameterClient

    world, log = procs.start("world", "/typed", "mode:=free", "rate_hz:=20")
    node = rclpy.create_node("typed_probe", namespace="/typed")
    executor.add_node(node)
    client = AsyncParameterClient(node, "/typed/world")
    spin_until(executor, lambda: client.services_are_ready() or world.poll() is not None,
               what="the world's parameter services")
    assert world.poll() is None, log.read_text()
    future = client.describe_parameters(["rate_hz", "trial_cycles", "mode"])
    spin_until(executor, future.done, what="describe_parameters")
    rate, cycles, mode = future.result().descriptors
    assert rate.type == ParameterType.PARAMETER_DOUBLE
    assert (rate.floating_point_range[0].from_value,
            rate.floating_point_range[0].to_value) == (0.01, 10000.0)
    assert cycles.integer_range[0].from_value == 0
    assert mode.additional_constraints == "one of lockstep, free"
    values = client.get_parameters(["rate_hz"])
    spin_until(executor, values.done, what="get_parameters")
    assert values.result().values[0].double_value == 20.0


# Which nodes get which signal, in turn, while the rest keep running: alone and together.
SIGNAL_ROUNDS = [
    {"world": signal.SIGINT},
    {"controller": signal.SIGTERM},
    {"recorder": signal.SIGINT},
    {"world": signal.SIGTERM, "controller": signal.SIGINT, "recorder": signal.SIGTERM},
    {"supervisor": signal.SIGINT},
    {"world": signal.SIGINT, "controller": signal.SIGINT, "supervisor": signal.SIGTERM,
     "recorder": signal.SIGINT},
]


@pytest.mark.parametrize("round_", range(len(SIGNAL_ROUNDS)))
def test_signals_end_every_node_quietly(ros, tmp_path, round_):
    """A lockstep graph evolving (supervisor), recorded, or a free-running world with its
    controller: the chosen nodes get their signal mid-stream; each ends with status 0 and
    nothing but log lines (no traceback, no 'context is invalid')."""
    rclpy, executor, procs = ros
    chosen = SIGNAL_ROUNDS[round_]
    ns = f"/sig{round_}"
    lockstep = "supervisor" in chosen
    world_params = [] if lockstep else ["mode:=free", "rate_hz:=2000", "n_envs:=200",
                                        "display_rate_hz:=0"]
    started = {"world": procs.start("world", ns, *world_params),
               "controller": procs.start("controller", ns, "controller:=reacher"
                                         if not lockstep else "controller:=normal"),
               "recorder": procs.start("recorder", ns, f"out:={tmp_path / 'bag'}")}
    if lockstep:
        started["supervisor"] = procs.start(
            "supervisor", ns, "population:=10", "parents:=2", "trials:=4", "cycles:=50",
            "generations:=500", f"out:={tmp_path / 'evolved'}")
    node = rclpy.create_node(f"sig_probe{round_}", namespace=ns)
    executor.add_node(node)
    heard = []
    from econet_ros.nodes import graph
    node.create_subscription(graph.message_class("touch"), "touch",
                             lambda m: heard.append(m.cycle), graph.qos("touch"))
    spin_until(executor, lambda: len(heard) > 200 or any(
        p.poll() is not None for p, _ in started.values()), timeout=120,
        what="the graph running")
    for name, sig in chosen.items():
        os.killpg(started[name][0].pid, sig)
    for name in chosen:
        proc, log = started[name]
        assert proc.wait(30) == 0, log.read_text()
        text = log.read_text()
        assert "Traceback" not in text and "context is invalid" not in text and \
            "Error occurred" not in text, text
    for name in started.keys() - chosen.keys():   # the others are still running
        assert started[name][0].poll() is None, started[name][1].read_text()
        procs.kill(started[name][0])

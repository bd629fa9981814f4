"""Controllers by name through the nodes: a controller from a package outside econet_ros
(tests/plugin_example) in the controller node, the reacher through the graph, a controller node
from outside econet_ros evolved by the supervisor (controller:=external), and the supervisor's
one-line errors for an external controller without its weight count."""
import os
import subprocess
import sys

import numpy as np
import pytest

from econet_ros.config import Config
from econet_ros.trials import run_trials
from econet_ros.world import World, sample_setups

from graph_helpers import REPO, call, ros_session, spin_until

pytestmark = pytest.mark.ros       # every test here starts ROS nodes

PLUGIN_DIR = REPO / "tests" / "plugin_example"


def with_plugin_env() -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = f"{PLUGIN_DIR}{os.pathsep}{env.get('PYTHONPATH', '')}"
    return env


@pytest.fixture(scope="module")
def ros(tmp_path_factory):
    yield from ros_session(tmp_path_factory, 215 + os.getpid() % 15, "plugin")


def test_outside_package_controller_through_the_node(ros):
    rclpy, executor, procs = ros
    from econet_msgs.msg import MuscleCommand
    from econet_msgs.srv import ResetTrials, SetWeights

    from econet_ros.nodes import graph as common
    sys.path.insert(0, str(PLUGIN_DIR))
    try:
        from econet_plugin_example import LinearController
    finally:
        sys.path.remove(str(PLUGIN_DIR))

    ns = "/plug"
    procs.start("world", ns)
    saved = os.environ.get("PYTHONPATH", "")
    os.environ["PYTHONPATH"] = with_plugin_env()["PYTHONPATH"]
    try:
        _, log = procs.start("controller", ns, "controller:=example-linear")
    finally:
        os.environ["PYTHONPATH"] = saved
    node = rclpy.create_node("plug_probe", namespace=ns)
    executor.add_node(node)
    commands = []
    answers = node.create_subscription(MuscleCommand, "muscle_command", commands.append,
                                       common.LOCKSTEP_QOS)
    spin_until(executor, lambda: answers.get_publisher_count() > 0, what="the plug-in's commands")
    config = Config()
    n = 3
    weights = np.random.default_rng(4).uniform(-2, 2, (n, 65))
    reply = call(executor, node.create_client(SetWeights, "set_weights"), SetWeights.Request(
        n_envs=n, weights_per_network=65, weights=common.f64(weights),
        network="example-linear"))
    assert reply.success, reply.message
    reset = call(executor, node.create_client(ResetTrials, "reset_trials"),
                 ResetTrials.Request(n_envs=n, cycles=5, seed=8))
    assert reset.success, reset.message
    spin_until(executor, lambda: sum(c.trial == reset.trial for c in commands) >= 5,
               what="five commands from the plug-in")
    got = [c for c in commands if c.trial == reset.trial]
    assert [c.cycle for c in got] == [0, 1, 2, 3, 4]
    # the same controller in process, on the same trial, gives the same commands
    world = World(n, config.model)
    obs = world.reset(sample_setups(np.random.default_rng(8), n, config.model))
    controller = LinearController(n, config)
    controller.load(weights)
    for command in got:
        motor = controller.act(obs)
        assert np.array_equal(common.as_f64(command.activation).reshape(n, 5), motor)
        obs = world.step(motor)
    assert "econet_plugin_example:LinearController" in log.read_text()


def test_reacher_through_the_graph_and_bad_name_at_the_node(ros):
    rclpy, executor, procs = ros
    from econet_msgs.msg import Touch
    from econet_msgs.srv import ResetTrials, SetWeights

    from econet_ros.nodes import graph as common
    from econet_ros.trials import TrialMeasures

    bad, bad_log = procs.start("controller", "/badname", "controller:=no-such-thing")
    assert bad.wait(60) == 2
    lines = [line for line in bad_log.read_text().splitlines() if line.strip()]
    assert lines == ["controller_node: error: unknown controller 'no-such-thing': not a "
                     "registered name (normal, random, reacher, three-layer) and not "
                     "module:Class"]

    ns = "/reach"
    procs.start("world", ns)
    procs.start("controller", ns, "controller:=reacher")
    node = rclpy.create_node("reach_probe", namespace=ns)
    executor.add_node(node)
    touch = {}
    sensed = node.create_subscription(Touch, "touch", lambda m: touch.setdefault(
        (m.trial, m.cycle), common.as_u8(m.contact).copy()), common.LOCKSTEP_QOS)
    spin_until(executor, lambda: sensed.get_publisher_count() > 0, what="the world's touch")
    n, cycles = 12, 100
    reply = call(executor, node.create_client(SetWeights, "set_weights"), SetWeights.Request(
        n_envs=n, weights_per_network=0, network="reacher"))
    assert reply.success, reply.message
    reset = call(executor, node.create_client(ResetTrials, "reset_trials"),
                 ResetTrials.Request(n_envs=n, cycles=cycles, seed=21))
    spin_until(executor, lambda: (reset.trial, cycles) in touch, timeout=60,
               what="the reacher's trial")
    contact = np.array([touch[reset.trial, t] for t in range(1, cycles + 1)]) != 0
    graph = TrialMeasures.from_contact(contact)
    assert graph.success.mean() >= 0.75
    config = Config()
    from econet_ros.plugins import make_controller
    local, _ = run_trials(World(n, config.model), make_controller("reacher", n, config),
                          sample_setups(np.random.default_rng(21), n, config.model), cycles)
    np.testing.assert_array_equal(graph.fitness, local.fitness)


def test_outside_controller_node_evolved_by_the_supervisor(ros, tmp_path):
    """A node econet_ros does not know (tests/plugin_example/econet_outside_node: rclpy and
    econet_msgs only) evolved through the graph with controller:=external n_weights:=65 writes
    the result folder that evolving the same arithmetic in process (example-linear) writes."""
    rclpy, executor, procs = ros
    ns, sizes = "/outside", ["--population", "6", "--parents", "2", "--trials", "3",
                             "--cycles", "20", "--generations", "2", "--seed", "4"]
    procs.start("world", ns)
    outside, outside_log = procs.start("outside", ns, module="econet_outside_node",
                                       env=with_plugin_env())
    params = [f"{sizes[i][2:]}:={sizes[i + 1]}" for i in range(0, len(sizes), 2)]
    sup, log = procs.start("supervisor", ns, *params, "controller:=external", "n_weights:=65",
                           f"out:={tmp_path / 'graph'}")
    assert sup.wait(180) == 0, log.read_text() + outside_log.read_text()
    assert outside.poll() is None, outside_log.read_text()
    local = subprocess.run([sys.executable, "-m", "econet_ros", "evolve", "--controller",
                            "example-linear", *sizes, "--quiet", "--out", str(tmp_path / "local")],
                           cwd=REPO, env=with_plugin_env(), capture_output=True, text=True,
                           timeout=120)
    assert local.returncode == 0, local.stderr
    for name in ("run.json", "metrics.csv", "genomes.npy", "fitness.npy", "best_genomes.npy"):
        assert (tmp_path / "graph" / "run-01" / name).read_bytes() == \
            (tmp_path / "local" / "run-01" / name).read_bytes(), name
    assert np.load(tmp_path / "graph" / "run-01" / "fitness.npy").max() > 0


@pytest.mark.parametrize("params, message", [
    (["controller:=external"], "controller:=external needs n_weights:=K"),
    (["n_weights:=5"], "n_weights is for controller:=external; the 'normal' controller has "
                       "its own weight count"),
])
def test_external_controller_needs_its_weight_count(params, message, tmp_path):
    proc = subprocess.run([sys.executable, "-m", "econet_ros.nodes.supervisor_node",
                           "--ros-args", *[x for p in params for x in ("-p", p)],
                           "-p", f"out:={tmp_path}"], cwd=REPO, capture_output=True,
                          text=True, timeout=60)
    assert proc.returncode == 2
    (line,) = proc.stderr.strip().splitlines()
    assert line.startswith(f"supervisor_node: error: {message}")

"""The graph composed in one process (graph_node): each node takes its own section of the command
line, the evolution writes what the three processes and `econet evolve` write, a recorder in
the process records all of it, an outside node sees every topic, service and parameter and
drives the composed world and controller in lockstep."""
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
import yaml

from graph_helpers import REPO, call, ros_session, spin_until

FILES = ("run.json", "metrics.csv", "genomes.npy", "fitness.npy", "best_genomes.npy")
SMALL = {"population": 10, "parents": 2, "trials": 4, "cycles": 60, "generations": 3, "seed": 3}
DOMAIN = 75 + 3 * (os.getpid() % 8)         # this module's, and two more for the demos


@pytest.fixture(scope="module")
def ros(tmp_path_factory):
    yield from ros_session(tmp_path_factory, DOMAIN, "composed")


def in_process_run(out, **changes):
    """What `econet evolve --runs 1` writes with the SMALL settings and ``changes`` (run-01)."""
    from econet_ros.config import Config
    from econet_ros.runs import run_condition

    sizes = {k: v for k, v in {**SMALL, **changes}.items() if k != "seed"}
    config = Config().replace(**{f"evolution.{k}": v for k, v in sizes.items()})
    run_condition(config, 1, SMALL["seed"], out, progress=False)
    return out / "run-01"


def assert_same_run(got, want):
    for name in FILES:
        assert (got / name).read_bytes() == (want / name).read_bytes(), name


def test_sections_go_to_their_nodes():
    from econet_ros.nodes.graph_node import split_sections

    shared, sections = split_sections([
        "--ros-args", "-r", "__ns:=/lab", "--", "controller", "--ros-args", "-p",
        "controller:=random", "supervisor", "--ros-args", "--params-file", "world", "-p",
        "generations:=2"])
    assert shared == ["--ros-args", "-r", "__ns:=/lab", "--"]
    assert sections == {"controller": ["--ros-args", "-p", "controller:=random"],
                        "supervisor": ["--ros-args", "--params-file", "world", "-p",
                                       "generations:=2"]}     # a file named world stays a file


@pytest.mark.parametrize("command, says", [
    (["scripts/node", "graph", "supervisor", "--help"],
     "usage: supervisor_node [--ros-args -p NAME:=VALUE ...]"),
    (["install/econet_ros/lib/econet_ros/graph_node", "--help"],
     "The graph composed in one process"),
])
def test_help_of_the_graph_and_of_one_of_its_nodes(command, says):
    proc = subprocess.run([str(REPO / command[0]), *command[1:]], cwd=REPO,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.startswith(says)


@pytest.mark.ros
def test_a_parameter_for_every_node_that_one_lacks_is_a_one_line_error():
    proc = subprocess.run([sys.executable, "-m", "econet_ros.nodes.graph_node", "--ros-args",
                           "-p", "generations:=2"], cwd=REPO, capture_output=True, text=True,
                          timeout=60, env={**os.environ, "ROS_DOMAIN_ID": str(DOMAIN)})
    assert proc.returncode == 2
    assert proc.stderr.strip().splitlines()[-1] == \
        "graph_node: error: world: unknown parameter(s) generations (see --help)"


@pytest.mark.ros
def test_composed_graph_evolves_as_in_process_and_serves_an_outside_node(ros, tmp_path):
    from econet_msgs.msg import EvolutionProgress, Retina
    from econet_msgs.srv import ResetTrials, SetWeights
    from rcl_interfaces.srv import GetParameters, ListParameters
    from econet_ros.nodes import graph as common

    rclpy, executor, _ = ros
    supervisor = [f"{k}:={v}" for k, v in {**SMALL, "out": tmp_path / "composed",
                                            "linger_sec": 60.0}.items()]
    log = tmp_path / "graph_node.log"
    with open(log, "w") as handle:
        proc = subprocess.Popen(
            [sys.executable, "-m", "econet_ros.nodes.graph_node", "--ros-args", "-r",
             "__ns:=/c", "--", "world", "--ros-args", "-p", "n_envs:=2", "supervisor",
             "--ros-args", *[x for p in supervisor for x in ("-p", p)], "recorder",
             "--ros-args", "-p", f"out:={tmp_path / 'bag'}", "-p", "topics:=retina"],
            cwd=REPO, stdout=handle, stderr=subprocess.STDOUT, start_new_session=True)
    try:
        node = rclpy.create_node("outside", namespace="/c")
        executor.add_node(node)
        progress, retina = [], []
        node.create_subscription(EvolutionProgress, "progress", progress.append,
                                 common.QOS["progress"])
        node.create_subscription(Retina, "retina", retina.append, common.reader_qos("retina"))
        spin_until(executor, lambda: len(progress) == 3 or proc.poll() is not None,
                   timeout=120, what="three generations' progress")
        assert [m.generation for m in progress] == [0, 1, 2], log.read_text()
        assert_same_run(tmp_path / "composed" / "run-01", in_process_run(tmp_path / "inproc"))

        topics = dict(node.get_topic_names_and_types())
        for topic in ("retina", "proprioception", "touch", "muscle_command", "trial_start",
                      "joint_states", "markers", "progress"):
            assert f"/c/{topic}" in topics, topics
        services = dict(node.get_service_names_and_types())
        assert services["/c/set_weights"] == ["econet_msgs/srv/SetWeights"]
        assert services["/c/reset_trials"] == ["econet_msgs/srv/ResetTrials"]
        # each node has its own parameters: n_envs went to the world only
        got = call(executor, node.create_client(GetParameters, "world/get_parameters"),
                   GetParameters.Request(names=["n_envs"]))
        assert got.values[0].integer_value == 2
        listed = call(executor, node.create_client(ListParameters, "world/list_parameters"),
                      ListParameters.Request())
        assert "generations" not in listed.result.names

        # the outside node drives the composed world and controller: lockstep, cycle by cycle
        spin_until(executor, lambda: node.count_publishers("retina") == 1, what="retina")
        retina.clear()
        weights = np.random.default_rng(1).uniform(-10, 10, (1, 64))
        reply = call(executor, node.create_client(SetWeights, "set_weights"),
                     SetWeights.Request(n_envs=3, weights_per_network=64,
                                        weights=common.f64(weights), network="normal"))
        assert reply.success, reply.message
        reply = call(executor, node.create_client(ResetTrials, "reset_trials"),
                     ResetTrials.Request(n_envs=3, cycles=40, seed=5))
        assert reply.success, reply.message
        spin_until(executor, lambda: len(retina) >= 41, what="40 cycles of the outside trial")
        assert [(m.trial, m.cycle, m.final) for m in retina] == \
            [(reply.trial, c, c == 40) for c in range(41)]
        # the recorder in the composed process hears the last cycle's message in its own
        # callback, which a loaded machine may run after ours: give it time before stopping
        settle = time.monotonic() + 2.0
        while time.monotonic() < settle:
            executor.spin_once(timeout_sec=0.05)
    finally:
        os.killpg(proc.pid, signal.SIGINT)
        proc.wait(30)
    assert proc.returncode == 0, log.read_text()
    # the recorder joined before the first generation and closed its bag at the end
    metadata = yaml.safe_load((tmp_path / "bag" / "metadata.yaml").read_text())
    counts = {t["topic_metadata"]["name"]: t["message_count"]
              for t in metadata["rosbag2_bagfile_information"]["topics_with_message_count"]}
    assert counts["/c/retina"] == 3 * (SMALL["cycles"] + 1) + 41


@pytest.mark.ros
def test_graph_demo_composed_and_apart_write_the_in_process_folder(tmp_path):
    settings = [f"{k}:={v}" for k, v in {**SMALL, "generations": 2, "linger_sec": 0.0}.items()]
    for offset, mode in ((1, ["--composed"]), (2, [])):
        out = tmp_path / (mode[0][2:] if mode else "apart")
        proc = subprocess.run([str(REPO / "scripts" / "graph-demo"), *mode, str(out),
                               *settings], cwd=REPO, capture_output=True, text=True,
                              timeout=180,
                              env={**os.environ, "ROS_DOMAIN_ID": str(DOMAIN + offset)})
        assert proc.returncode == 0, proc.stdout + proc.stderr
    want = in_process_run(tmp_path / "inproc", generations=2)
    assert_same_run(tmp_path / "composed" / "run-01", want)
    assert_same_run(tmp_path / "apart" / "run-01", want)

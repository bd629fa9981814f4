"""The node graph under bad input and faults (issue 16), each probe once and small: a burst of
calls and a paused reader of the lockstep topics during a supervisor run. Every process must
live on without a traceback, and every result folder must equal the undisturbed in-process
run's, byte for byte.

A process killed or paused stays listed until its DDS lease runs out (Fast DDS: 20 s). The
graph's nodes here announce a 3 s lease (a Fast DDS profile), so that a killed node costs
seconds; the paused monitor keeps the default, so that the graph goes on sending to it."""
import os
import signal

import numpy as np
import pytest

from econet_ros.config import Config
from econet_ros.runs import run_condition

from graph_helpers import call, ros_session, spin_until

SMALL = {"population": 6, "parents": 2, "trials": 3, "cycles": 30}
N_ENVS = SMALL["population"] * SMALL["trials"]
FILES = ("run.json", "metrics.csv", "genomes.npy", "fitness.npy", "best_genomes.npy")
SHORT_LEASE = """<?xml version="1.0" encoding="UTF-8" ?>
<dds xmlns="http://www.eprosima.com"><profiles>
  <participant profile_name="econet_test_lease" is_default_profile="true"><rtps><builtin>
    <discovery_config><leaseDuration><sec>3</sec></leaseDuration>
      <leaseAnnouncement><sec>1</sec></leaseAnnouncement></discovery_config>
  </builtin></rtps></participant>
</profiles></dds>
"""
# A monitor as a user might write one: every lockstep topic, reliable and keep-all (the most
# demanding reader there is); it prints "matched" once each topic has a publisher.
MONITOR = """
import sys, time, rclpy
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
from econet_ros.nodes import graph
from econet_ros.topics import LOCKSTEP
rclpy.init(args=sys.argv)
node = rclpy.create_node("monitor")
qos = QoSProfile(history=HistoryPolicy.KEEP_ALL, reliability=ReliabilityPolicy.RELIABLE)
subs = [node.create_subscription(graph.message_class(t), t, lambda m: None, qos, raw=True)
        for t in LOCKSTEP]
while not all(s.get_publisher_count() for s in subs):
    rclpy.spin_once(node, timeout_sec=0.05)
time.sleep(0.5)                 # for the publishers to match this node in turn
print("matched", flush=True)
rclpy.spin(node)
"""


@pytest.fixture(scope="module")
def ros(tmp_path_factory):
    yield from ros_session(tmp_path_factory, 60 + os.getpid() % 15, "reliability")


@pytest.fixture(scope="module")
def lease_env(tmp_path_factory):
    """The environment of this module's node processes: the short-lease profile."""
    folder = tmp_path_factory.mktemp("lease")
    (folder / "lease.xml").write_text(SHORT_LEASE)
    return {**os.environ, "FASTDDS_DEFAULT_PROFILES_FILE": str(folder / "lease.xml")}


@pytest.fixture(scope="module")
def monitor_env(tmp_path_factory):
    """The monitor's: importable as a module, and with the default lease (20 s), so that the
    graph goes on sending to it while it is paused."""
    folder = tmp_path_factory.mktemp("monitor")
    (folder / "econet_test_monitor.py").write_text(MONITOR)
    return {**os.environ, "PYTHONPATH": f"{folder}:{os.environ.get('PYTHONPATH', '')}"}


def config(generations):
    return Config().replace(**{f"evolution.{k}": v for k, v in SMALL.items()},
                            **{"evolution.generations": generations})


def supervisor_params(out, generations):
    params = {**SMALL, "generations": generations, "seed": 3, "out": str(out),
              "stall_timeout_sec": 1.0, "service_timeout_sec": 2.0}
    return [f"{k}:={v}" for k, v in params.items()]


def start_graph(procs, ns, env):
    """World and controller in ``ns``; {node: (process, log)}."""
    return {node: procs.start(node, ns, env=env) for node in ("world", "controller")}


def says(log, text):
    """A condition for spin_until: ``text`` is in the log."""
    return lambda: text in log.read_text()


def assert_same_as_in_process(out, generations, tmp_path):
    run_condition(config(generations), 1, 3, tmp_path / "inproc", progress=False)
    for name in FILES:
        assert (out / "run-01" / name).read_bytes() == \
            (tmp_path / "inproc" / "run-01" / name).read_bytes(), name


def assert_no_traceback(*logs):
    for log in logs:
        text = log.read_text()
        assert "Traceback" not in text and "could not publish" not in text, text


def probe(rclpy, executor, namespace):
    node = rclpy.create_node("probe", namespace=namespace)
    executor.add_node(node)
    return node


def test_a_burst_of_calls_gets_every_reply(ros, lease_env):
    """300 calls at once all get their reply; world and controller serve on."""
    rclpy, executor, procs = ros
    from econet_msgs.srv import ResetTrials, SetWeights
    from econet_ros.nodes import graph as common

    (world, world_log), (controller, controller_log) = start_graph(
        procs, "/rreq", lease_env).values()
    node = probe(rclpy, executor, "/rreq")
    reset, weights = common.client(node, "reset_trials"), common.client(node, "set_weights")
    good = SetWeights.Request(n_envs=N_ENVS, weights_per_network=160,
                              weights=common.f64(np.zeros((SMALL["population"], 160))))
    assert call(executor, weights, good).success       # both ends matched before the burst
    futures = [weights.call_async(good) for _ in range(300)]
    spin_until(executor, lambda: all(f.done() for f in futures), timeout=120,
               what="300 replies")
    assert all(f.result().success for f in futures)
    assert call(executor, reset, ResetTrials.Request(n_envs=N_ENVS, cycles=5)).success
    assert world.poll() is None and controller.poll() is None
    assert_no_traceback(world_log, controller_log)


def test_a_paused_monitor_cannot_hold_up_the_graph(ros, lease_env, monitor_env, tmp_path):
    """A monitor reading every lockstep topic (reliable, keep-all) is paused (SIGSTOP) through
    a whole run of more than 5,000 cycles, where keep-all writers failed after about 4,500
    messages (when they came within the monitor's DDS lease, 20 s): nothing fails to publish,
    the run equals the undisturbed one, and the monitor reads on once continued (SIGCONT)."""
    rclpy, executor, procs = ros
    ns, out, generations = "/rpause", tmp_path / "graph", 170
    assert generations * (SMALL["cycles"] + 1) > 5000
    (_, world_log), (_, controller_log) = start_graph(procs, ns, lease_env).values()
    monitor, monitor_log = procs.start("monitor", ns, module="econet_test_monitor",
                                       env=monitor_env)
    spin_until(executor, says(monitor_log, "matched"), timeout=120,
               what="the monitor to match the graph")
    os.kill(monitor.pid, signal.SIGSTOP)
    try:
        sup, log = procs.start("supervisor", ns, *supervisor_params(out, generations),
                               env=lease_env)
        spin_until(executor, lambda: sup.poll() is not None, timeout=180,
                   what="the supervisor")
        assert sup.returncode == 0, log.read_text()
    finally:
        os.kill(monitor.pid, signal.SIGCONT)
    assert "testing the generation again" not in log.read_text()
    assert monitor.poll() is None, monitor_log.read_text()
    assert_same_as_in_process(out, generations, tmp_path)
    assert_no_traceback(log, world_log, controller_log, monitor_log)

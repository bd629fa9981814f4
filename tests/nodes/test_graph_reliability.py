"""The node graph under bad input and faults, each probe once and small: malformed
sensor messages and requests, a burst of calls, strangers on the graph's topics and services,
two graphs in one namespace, a paused reader of the lockstep topics and nodes killed and
restarted during a supervisor run. Every process must live on without a traceback, and every
result folder must equal the undisturbed in-process run's, byte for byte.

A process killed or paused stays listed until its DDS lease runs out (Fast DDS: 20 s). The
graph's nodes here announce a 3 s lease (a Fast DDS profile), so that a killed node costs
seconds; the paused monitor keeps the default, so that the graph goes on sending to it, and so
does the graph whose controller is killed for good, as a user's would."""
import array
import os
import signal
import time

import numpy as np
import pytest

from econet_ros.config import Config
from econet_ros.plugins import make_controller
from econet_ros.runs import run_condition
from econet_ros.topics import MAX_ENVS

from graph_helpers import call, ros_session, spin_until

pytestmark = pytest.mark.ros       # every test here starts ROS nodes

SMALL = {"population": 6, "parents": 2, "trials": 3, "cycles": 30}
N_ENVS = SMALL["population"] * SMALL["trials"]
WEIGHTS = make_controller("normal", 1, Config()).n_params     # the default network's
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


def start_graph(procs, ns, env, out=None, generations=0):
    """World and controller in ``ns``, and with ``out`` a supervisor evolving into it;
    {node: (process, log)}."""
    started = {node: procs.start(node, ns, env=env) for node in ("world", "controller")}
    if out is not None:
        started["supervisor"] = procs.start("supervisor", ns,
                                            *supervisor_params(out, generations), env=env)
    return started


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


def keep_doing(executor, action, until, what):
    """Repeat action() between spins until until() holds (fails after a generous timeout)."""
    spin_until(executor, lambda: action() or until(), timeout=60, what=what)


def probe(rclpy, executor, namespace):
    node = rclpy.create_node("probe", namespace=namespace)
    executor.add_node(node)
    return node


def test_bad_sensor_messages_are_refused_and_the_controller_keeps_serving(ros, lease_env):
    """Self-consistent but malformed sensor messages, and NaN or infinite values: no command
    for any, a log line for each kind; the controller answers the next good cycle."""
    rclpy, executor, procs = ros
    from econet_msgs.msg import MuscleCommand, Proprioception, Retina, Touch
    from econet_ros.nodes import graph as common

    controller, log = procs.start("controller", "/rbad", "n_envs:=2", env=lease_env)
    node = probe(rclpy, executor, "/rbad")
    commands = []
    node.create_subscription(MuscleCommand, "muscle_command", lambda m: commands.append(m.cycle),
                             common.LOCKSTEP_QOS)
    pubs = {name: node.create_publisher(kind, name, common.LOCKSTEP_QOS)
            for name, kind in (("retina", Retina), ("proprioception", Proprioception),
                               ("touch", Touch))}

    def send(cycle, n=2, units=8, touch_n=2, retina=0.2, stretch=0.5, contact=0):
        head = dict(trial=1, cycle=cycle)
        pubs["touch"].publish(Touch(**head, n_envs=touch_n,
                                    contact=array.array("B", [contact] * touch_n)))
        pubs["proprioception"].publish(Proprioception(**head, n_envs=n,
                                                      stretch=common.f64([stretch] * 4 * n)))
        pubs["retina"].publish(Retina(**head, n_envs=n, units_per_env=units,
                                      activation=common.f64([retina] * units * n),
                                      fixated=array.array("B", [0] * n)))

    # Good cycles until one is answered: both sides have matched then.
    cycle = 0
    while not commands:
        cycle += 1
        assert cycle < 60, "the controller never answered a good cycle"
        send(cycle)
        for _ in range(10):
            executor.spin_once(timeout_sec=0.05)
    bad = [dict(units=4), dict(units=0), dict(touch_n=3), dict(touch_n=1),
           dict(retina=float("nan")), dict(stretch=float("inf")), dict(contact=2)]
    first_bad = cycle + 1
    for offset, fields in enumerate(bad):
        send(first_bad + offset, **fields)
    last = first_bad + len(bad)
    send(last)
    spin_until(executor, lambda: last in commands, what="the command for the last good cycle")
    assert not set(commands) & set(range(first_bad, last))
    assert controller.poll() is None
    text = log.read_text()
    # one line per kind within 5 s: units_per_env 0 and touch for 1 are the kinds before them
    for line in ("retina has units_per_env=4, the model has 8",
                 "touch for 3 environment(s), but the controller has 2",
                 "retina.activation contains NaN or infinite values",
                 "proprioception.stretch contains NaN or infinite values",
                 "touch.contact holds 2, expected 0 or 1"):
        assert line in text, text
    assert_no_traceback(log)


def test_bad_requests_get_error_replies_and_a_burst_gets_every_reply(ros, lease_env):
    """Batches beyond any sane size are refused before anything is allocated; 300 calls at
    once all get their reply; world and controller serve on."""
    rclpy, executor, procs = ros
    from econet_msgs.srv import ResetTrials, SetWeights
    from econet_ros.nodes import graph as common

    (world, world_log), (controller, controller_log) = start_graph(
        procs, "/rreq", lease_env).values()
    node = probe(rclpy, executor, "/rreq")
    reset, weights = common.client(node, "reset_trials"), common.client(node, "set_weights")
    for n in (2 ** 32 - 1, 2 ** 31, MAX_ENVS + 1):
        reply = call(executor, reset, ResetTrials.Request(n_envs=n, cycles=5))
        assert not reply.success and \
            f"n_envs is {n}; a world holds at most {MAX_ENVS} environments" in reply.message
        reply = call(executor, weights, SetWeights.Request(
            n_envs=n, weights_per_network=WEIGHTS, weights=common.f64(np.zeros((3, WEIGHTS)))))
        assert not reply.success and \
            f"n_envs must be between 1 and {MAX_ENVS}, got {n}" in reply.message
    good = SetWeights.Request(n_envs=N_ENVS, weights_per_network=WEIGHTS,
                              weights=common.f64(np.zeros((SMALL["population"], WEIGHTS))))
    assert call(executor, weights, good).success       # both ends matched before the burst
    futures = [weights.call_async(good) for _ in range(300)]
    spin_until(executor, lambda: all(f.done() for f in futures), timeout=120,
               what="300 replies")
    assert all(f.result().success for f in futures)
    assert call(executor, reset, ResetTrials.Request(n_envs=N_ENVS, cycles=5)).success
    assert world.poll() is None and controller.poll() is None
    assert_no_traceback(world_log, controller_log)


def test_strangers_stop_the_generation_and_change_nothing(ros, lease_env, tmp_path):
    """During a supervisor run another node publishes touch (all contact, stamped as the
    world's cycles), then muscle commands (answering the world's cycles), then swaps the
    controller's weights. Each time the supervisor stops the generation and says why, the
    world, controller and supervisor ignore the stranger's messages, and once it is gone the
    generation is tested again: the results equal the undisturbed run's."""
    rclpy, executor, procs = ros
    from econet_msgs.msg import MuscleCommand, Touch
    from econet_msgs.srv import SetWeights
    from econet_ros.nodes import graph as common

    ns, out, generations = "/rstr", tmp_path / "graph", 300     # long enough for three visits
    (_, world_log), (_, controller_log), (sup, log) = start_graph(
        procs, ns, lease_env, out, generations).values()
    stranger = rclpy.create_node("stranger", namespace=ns)
    executor.add_node(stranger)
    spin_until(executor, says(log, f"generation 2/{generations}"), timeout=120,
               what="the run to start")

    # The stranger publishes as if it were the world, stamped like the world's last cycle
    # (all contact), until the supervisor has stopped and the controller has ignored it.
    heard = [(1, 0)]
    listen = stranger.create_subscription(Touch, "touch", lambda m: heard.append(
        (m.trial, m.cycle)), common.LOCKSTEP_QOS)
    touch = stranger.create_publisher(Touch, "touch", common.LOCKSTEP_QOS)
    keep_doing(executor, lambda: touch.publish(Touch(
        trial=heard[-1][0], cycle=heard[-1][1], n_envs=N_ENVS,
        contact=array.array("B", [1] * N_ENVS))),
        until=lambda: says(log, "2 publishers of touch (nodes /rstr/stranger, /rstr/world)")()
        and says(controller_log, "ignored /rstr/touch from /rstr/stranger")(),
        what="the supervisor to stop and the controller to ignore the stranger's touch")
    stranger.destroy_publisher(touch)

    # Then as if it were the controller, answering the world's last cycle.
    commands = stranger.create_publisher(MuscleCommand, "muscle_command", common.LOCKSTEP_QOS)
    keep_doing(executor, lambda: commands.publish(MuscleCommand(
        trial=heard[-1][0], cycle=heard[-1][1], n_envs=N_ENVS,
        activation=common.f64(np.ones(5 * N_ENVS)))),
        until=lambda: says(log, "2 publishers of muscle_command (nodes /rstr/controller, "
                                "/rstr/stranger)")()
        and says(world_log, "ignored /rstr/muscle_command from /rstr/stranger")(),
        what="the supervisor to stop and the world to ignore the stranger's commands")
    stranger.destroy_publisher(commands)
    stranger.destroy_subscription(listen)

    swap = common.client(stranger, "set_weights")
    reply = call(executor, swap, SetWeights.Request(
        n_envs=N_ENVS, weights_per_network=WEIGHTS,
        weights=common.f64(np.full((SMALL["population"], WEIGHTS), 3.0))))
    assert reply.success                # the controller cannot tell who calls it
    spin_until(executor, says(log, "2 clients of set_weights"),
               what="the supervisor to see the second client")
    stranger.destroy_client(swap)

    spin_until(executor, lambda: sup.poll() is not None, timeout=120, what="the supervisor")
    assert sup.returncode == 0, log.read_text()
    assert "testing the generation again" in log.read_text()
    assert_same_as_in_process(out, generations, tmp_path)
    assert_no_traceback(log, world_log, controller_log)


def test_two_graphs_in_one_namespace_refuse_loudly(ros, lease_env, tmp_path):
    """Two whole graphs started in one namespace: neither supervisor tests anything while the
    other graph is there, and says why; once one graph has gone, the other's run equals the
    undisturbed one."""
    rclpy, executor, procs = ros
    ns, generations = "/rtwin", 3
    graphs = [start_graph(procs, ns, lease_env) for _ in (1, 2)]
    watch = probe(rclpy, executor, ns)          # both graphs' nodes up before any supervisor
    spin_until(executor, lambda: watch.count_publishers(f"{ns}/retina") == 2
               and watch.count_publishers(f"{ns}/muscle_command") == 2, timeout=120,
               what="two worlds and two controllers")
    for k, g in enumerate(graphs, 1):
        g["supervisor"] = procs.start("supervisor", ns, *supervisor_params(
            tmp_path / f"graph{k}", generations), env=lease_env)
    spin_until(executor, lambda: all(says(g["supervisor"][1], "waiting for the graph: 2 "
                                          "publishers of retina")() for g in graphs),
               timeout=120, what="both supervisors to refuse")
    for proc, _ in graphs[1].values():
        procs.kill(proc)                          # SIGINT: gone from the graph at once
    sup, log = graphs[0]["supervisor"]
    spin_until(executor, lambda: sup.poll() is not None, timeout=120, what="the supervisor")
    assert sup.returncode == 0, log.read_text()
    assert_same_as_in_process(tmp_path / "graph1", generations, tmp_path)
    assert_no_traceback(*[log for g in graphs for _, log in g.values()])


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


def test_killed_and_restarted_nodes_change_nothing(ros, lease_env, tmp_path):
    """During a supervisor run the world is killed (SIGKILL) and restarted at once; later the
    controller is killed and restarted only after the supervisor noticed. The supervisor tests
    the interrupted generations again, and the results equal the undisturbed run's."""
    rclpy, executor, procs = ros
    ns, out, generations = "/rkill", tmp_path / "graph", 60
    (world, world_log), (controller, controller_log), (sup, log) = start_graph(
        procs, ns, lease_env, out, generations).values()
    logs = [log, world_log, controller_log]

    spin_until(executor, says(log, f"generation 15/{generations}"), timeout=120,
               what="generation 15")
    procs.kill(world, signal.SIGKILL)
    logs.append(procs.start("world", ns, env=lease_env)[1])                # promptly

    spin_until(executor, says(log, f"generation 35/{generations}"), timeout=120,
               what="generation 35")
    noticed = log.read_text().count("testing the generation again")
    procs.kill(controller, signal.SIGKILL)
    spin_until(executor, lambda: log.read_text().count("testing the generation again")
               > noticed, what="the supervisor to notice the controller is gone")
    logs.append(procs.start("controller", ns, env=lease_env)[1])           # late

    spin_until(executor, lambda: sup.poll() is not None, timeout=180, what="the supervisor")
    assert sup.returncode == 0, log.read_text()
    assert noticed >= 1             # the world's kill was noticed too
    assert_same_as_in_process(out, generations, tmp_path)
    assert_no_traceback(*logs)


def test_a_killed_controller_is_noticed_within_the_stall_timeout(ros, tmp_path):
    """The controller killed (SIGKILL) mid-trial and not restarted, everything at its defaults
    (a 3 s stall timeout, the 20 s DDS lease): the supervisor says so within the stall timeout,
    although the world sends the stalled cycle's sensors again every second (each repeat used
    to restart the supervisor's stall clock: the line came when the lease ran out, 20 s)."""
    rclpy, executor, procs = ros
    from econet_ros.nodes import graph as common

    ns, stall, cycles = "/rstall", 3.0, 300         # a trial long enough to kill it in
    env = {k: v for k, v in os.environ.items() if k != "FASTDDS_DEFAULT_PROFILES_FILE"}
    params = {**SMALL, "cycles": cycles, "generations": 100, "seed": 3, "out": str(tmp_path)}
    (world, _), (controller, _) = start_graph(procs, ns, env).values()
    sup, log = procs.start("supervisor", ns, *[f"{k}:={v}" for k, v in params.items()],
                           env=env)
    heard = []
    probe(rclpy, executor, ns).create_subscription(
        common.message_class("touch"), "touch", lambda m: heard.append(m.cycle),
        common.reader_qos("touch"))
    spin_until(executor, says(log, "generation 2/100"), timeout=120, what="the run to start")
    heard.clear()
    spin_until(executor, lambda: any(c > cycles // 3 for c in heard), what="a trial under way")
    killed = time.time()
    procs.kill(controller, signal.SIGKILL)
    spin_until(executor, says(log, "testing the generation again"), timeout=40,
               what="the supervisor to notice")
    line = next(line for line in log.read_text().splitlines()
                if "testing the generation again" in line)
    stamp = float(line.split("] [")[1])             # the log's own time of the line
    for proc in (sup, world):
        procs.kill(proc)
    assert f"no new cycle for {stall:g} s after cycle" in line, line
    # a cycle takes milliseconds; the second covers the scheduling of a loaded machine
    assert stamp - killed < stall + 1.0, f"{stamp - killed:.1f} s after the kill: {line}"

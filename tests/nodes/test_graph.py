"""The ROS 2 node graph, with world, controller and supervisor as separate OS processes:
topics and types, the reset and weight services and their error replies, lockstep, equivalence
with the in-process engine, and evolution runs (also across a controller that vanishes)."""
import array
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

os.environ["ROS_DOMAIN_ID"] = str(100 + os.getpid() % 100)   # no cross-talk with other runs

import rclpy  # noqa: E402
from rclpy.parameter import Parameter  # noqa: E402

from econet_msgs.msg import (EvolutionProgress, MuscleCommand, Proprioception, Retina,  # noqa: E402
                              Touch)
from econet_msgs.srv import ResetTrials, SetWeights  # noqa: E402
from econet_ros.config import Config  # noqa: E402
from econet_ros.controllers import RandomMovement  # noqa: E402
from econet_ros.evolution import Evaluator, InProcessEvaluator, initial_genomes  # noqa: E402
from econet_ros.runs import run_condition  # noqa: E402
from econet_ros.nodes import graph as common  # noqa: E402
from econet_ros.nodes.runner import make_executor  # noqa: E402
from econet_ros.nodes.supervisor_node import SupervisorNode  # noqa: E402
from econet_ros.world import TrialSetup, World  # noqa: E402

from graph_helpers import REPO, Processes, call, spin_until  # noqa: E402

pytestmark = pytest.mark.ros       # every test here starts ROS nodes

SMALL = {"population": 10, "parents": 2, "trials": 4, "cycles": 60}
FILES = ("run.json", "metrics.csv", "genomes.npy", "fitness.npy", "best_genomes.npy")


def small_config(condition="normal", generations=3):
    return Config().replace(**{f"evolution.{k}": v for k, v in SMALL.items()},
                            **{"evolution.condition": condition,
                               "evolution.generations": generations})


@pytest.fixture(scope="module")
def procs(tmp_path_factory):
    p = Processes(tmp_path_factory.mktemp("graph-logs"))
    yield p
    p.stop_all()


@pytest.fixture(scope="module")
def ros():
    rclpy.init()
    executor = make_executor()
    yield executor
    rclpy.try_shutdown()


def make_node(executor, name, namespace):
    node = rclpy.create_node(name, namespace=namespace)
    executor.add_node(node)
    return node


@pytest.fixture(scope="module")
def graph(procs, ros):
    """World and four-layer controller in namespace /g (shared by several tests)."""
    procs.start("world", "/g")
    procs.start("controller", "/g")
    node = make_node(ros, "probe", "/g")
    return node


def test_topics_services_and_types(graph, ros):
    expected_topics = {
        "/g/retina": "econet_msgs/msg/Retina",
        "/g/proprioception": "econet_msgs/msg/Proprioception",
        "/g/touch": "econet_msgs/msg/Touch",
        "/g/muscle_command": "econet_msgs/msg/MuscleCommand",
        "/g/joint_states": "sensor_msgs/msg/JointState",
        "/g/markers": "visualization_msgs/msg/MarkerArray",
    }
    expected_services = {"/g/reset_trials": "econet_msgs/srv/ResetTrials",
                         "/g/set_weights": "econet_msgs/srv/SetWeights"}

    def listed(getter, expected):
        have = dict((name, types) for name, types in getter())
        return all(have.get(name) == [kind] for name, kind in expected.items())

    spin_until(ros, lambda: listed(graph.get_topic_names_and_types, expected_topics)
               and listed(graph.get_service_names_and_types, expected_services),
               what="the graph's topics and services")
    # world publishes sensors and display topics, controller publishes commands
    assert graph.count_publishers("/g/retina") == 1
    assert graph.count_subscribers("/g/retina") == 1
    assert graph.count_publishers("/g/muscle_command") == 1
    assert graph.count_subscribers("/g/muscle_command") == 1


def test_reset_service_replies_and_errors(graph, ros):
    client = graph.create_client(ResetTrials, "reset_trials")
    bad = [
        (ResetTrials.Request(n_envs=2, cycles=5, object_xy=common.f64([[0.0, 1.0], [20, 0]])),
         "out of reach"),
        (ResetTrials.Request(n_envs=2, cycles=5, body_deg=common.f64([0.0, 1.0, 2.0])),
         "body_deg has 3 values, expected 2"),
        (ResetTrials.Request(n_envs=1, cycles=5, shoulder_deg=common.f64([190.0])),
         "shoulder angles must be between 0 and 180 degrees, got 190"),
        (ResetTrials.Request(n_envs=1, cycles=5, body_deg=common.f64([1e300])),
         "body angles must be between -360 and 360 degrees, got 1e+300"),
        (ResetTrials.Request(n_envs=1, cycles=5, elbow_deg=common.f64([np.nan])),
         "NaN"),
    ]
    before = call(ros, client, ResetTrials.Request(n_envs=2, cycles=5, seed=3))
    assert before.success and before.n_envs == 2
    for request, text in bad:
        reply = call(ros, client, request)
        assert not reply.success
        assert text in reply.message
        assert reply.trial == before.trial            # refused: no new trial started
        assert reply.n_envs == before.n_envs
    after = call(ros, client, ResetTrials.Request(n_envs=3, cycles=5, seed=4))
    assert after.success and after.trial == before.trial + 1 and after.n_envs == 3


def test_weight_service_errors_keep_old_weights(graph, ros):
    """Refused swaps say why; the controller still answers with the weights it had."""
    client = graph.create_client(SetWeights, "set_weights")
    config = small_config()
    n = 3
    k = InProcessEvaluator(config).n_weights
    good = np.random.default_rng(5).uniform(-10, 10, (n, k))
    ok = call(ros, client, SetWeights.Request(n_envs=n, weights_per_network=k,
                                              weights=common.f64(good), network="normal"))
    assert ok.success, ok.message
    nan = good.copy()
    nan[1, 2] = np.nan
    big = good.copy()
    big[0, 0] = 11.0
    cases = [
        (SetWeights.Request(n_envs=n, weights_per_network=k - 1,
                            weights=common.f64(good[:, :-1])), f"network has {k} weights"),
        (SetWeights.Request(n_envs=n, weights_per_network=k, weights=common.f64(good[:2])),
         "with n_networks dividing n_envs = 3"),
        (SetWeights.Request(n_envs=n, weights_per_network=k,
                            weights=common.f64(good.ravel()[:-1])), "expected n_networks x"),
        (SetWeights.Request(n_envs=n, weights_per_network=k, weights=common.f64(nan)), "NaN"),
        (SetWeights.Request(n_envs=n, weights_per_network=k, weights=common.f64(big)),
         "outside the allowed range"),
        (SetWeights.Request(n_envs=n, weights_per_network=k, weights=common.f64(good),
                            network="three-layer"), "runs the 'normal' network"),
    ]
    for request, text in cases:
        reply = call(ros, client, request)
        assert not reply.success
        assert text in reply.message, reply.message

    # The controller still holds `good`: drive one cycle by hand and compare its command.
    commands = []
    graph.create_subscription(MuscleCommand, "muscle_command", commands.append,
                              common.LOCKSTEP_QOS)
    reset = graph.create_client(ResetTrials, "reset_trials")
    reply = call(ros, reset, ResetTrials.Request(n_envs=n, cycles=1, seed=9))
    spin_until(ros, lambda: any(c.trial == reply.trial for c in commands),
               what="the controller's command")
    command = next(c for c in commands if c.trial == reply.trial)
    assert command.cycle == 0 and command.n_envs == n
    world = World(n, config.model)
    from econet_ros.world import sample_setups
    obs = world.reset(sample_setups(np.random.default_rng(9), n, config.model))
    from econet_ros.plugins import make_controller
    controller = make_controller("normal", n, config)
    controller.load(good)
    expected = controller.act(obs)
    assert np.array_equal(common.as_f64(command.activation).reshape(n, 5), expected)


def test_lockstep_world_steps_once_per_matching_command(procs, ros):
    """A world alone (the test is its controller): duplicate, future, NaN and wrong-length
    commands are rejected with a log line (one per kind) and never step it; a matching command
    steps exactly once, as the in-process World does. A cycle left unanswered for RESEND_SEC
    has its sensors sent again, byte for byte."""
    _, log = procs.start("world", "/solo")
    node = make_node(ros, "solo_probe", "/solo")
    heard = {}                              # (trial, cycle) -> every message of that cycle
    sensed = node.create_subscription(Proprioception, "proprioception", lambda m: heard.setdefault(
        (m.trial, m.cycle), []).append(m), common.LOCKSTEP_QOS)
    pub = node.create_publisher(MuscleCommand, "muscle_command", common.LOCKSTEP_QOS)
    model = Config().model
    setup = TrialSetup(np.array([[20.0, 5.0], [0.0, -30.0]]), np.array([10.0, 200.0]),
                       np.array([90.0, 30.0]), np.array([45.0, 170.0]))
    reset = node.create_client(ResetTrials, "reset_trials")
    spin_until(ros, lambda: pub.get_subscription_count() > 0 and sensed.get_publisher_count() > 0,
               what="the world, matched both ways")
    reply = call(ros, reset, ResetTrials.Request(
        n_envs=2, cycles=10, object_xy=common.f64(setup.object_xy), body_deg=common.f64(setup.body),
        shoulder_deg=common.f64(setup.shoulder), elbow_deg=common.f64(setup.elbow)))
    assert reply.success, reply.message
    trial = reply.trial
    spin_until(ros, lambda: len(heard) >= 1, what="cycle 0")

    rng = np.random.default_rng(2)
    m0, m1 = rng.random((2, 5)), rng.random((2, 5))
    nan = m1.copy()
    nan[0, 0] = np.nan

    def send(cycle, motor, trial=trial, n=2):
        pub.publish(MuscleCommand(trial=trial, cycle=cycle, n_envs=n,
                                  activation=common.f64(motor)))

    send(0, m0)
    spin_until(ros, lambda: len(heard) >= 2, what="cycle 1")
    send(0, m0)                       # duplicate: already applied
    send(5, m1)                       # a future cycle
    send(1, m1, trial=trial + 7)      # another trial
    send(1, nan)                      # NaN
    send(1, m1[:1], n=1)              # wrong number of environments
    send(1, m1[:1], n=2)              # wrong length
    send(1, m1)                       # the one that counts
    spin_until(ros, lambda: len(heard) >= 3, what="cycle 2")
    send(2, m1)
    spin_until(ros, lambda: len(heard) >= 4, what="cycle 3")

    assert list(heard) == [(trial, c) for c in range(4)]
    world = World(2, model)
    world.reset(setup)
    for motor in (m0, m1, m1):
        obs = world.step(motor)
    assert np.array_equal(common.as_f64(heard[trial, 3][0].stretch).reshape(2, 4), obs.proprio)

    spin_until(ros, lambda: len(heard[trial, 3]) >= 2, what="cycle 3 sent again")
    assert list(heard) == [(trial, c) for c in range(4)]      # the same cycle, not a new one
    for again in heard.values():
        assert all(bytes(m.stretch) == bytes(again[0].stretch) for m in again)
    spin_until(ros, lambda: f"no command for trial {trial} cycle 3 in 1 s: sent its sensors "
               "again" in log.read_text(), what="the world to say it sent cycle 3 again")
    text = log.read_text()
    # one line per kind of rejection (a flood of one kind is one line every 5 s)
    assert text.count("rejected muscle command") == 3, text
    assert text.count("the world is at trial") == text.count("NaN") == \
        text.count("the world has 2 environment(s)") == 1, text


def equivalence(procs, ros, namespace, condition, generation=1):
    """Test one generation through the graph (this process as supervisor) and in-process."""
    procs.start("world", namespace)
    procs.start("controller", namespace, f"controller:={condition}")
    config = small_config(condition)
    sup = SupervisorNode(namespace=namespace, parameter_overrides=[
        Parameter(k, value=v) for k, v in {**SMALL, "condition": condition,
                                          "out": "/tmp/unused-econet-graph-test"}.items()])
    sup.evaluator.executor = ros
    ros.add_node(sup)
    sup.evaluator.wait_for_graph()
    evaluator = InProcessEvaluator(config)
    genomes = initial_genomes(config, evaluator.n_weights, 3, 1)
    graph_result = sup.evaluator.test_generation(genomes, 3, 1, generation)
    expected = evaluator.test_generation(genomes, 3, 1, generation)
    return graph_result, expected, sup.evaluator


@pytest.mark.parametrize("condition", ["normal", "three-layer", "random"])
def test_fitness_through_graph_equals_in_process(procs, ros, condition):
    got, want, sup = equivalence(procs, ros, f"/eq_{condition.replace('-', '_')}", condition)
    assert isinstance(sup, Evaluator)
    assert got.fitness.shape == (SMALL["population"],)
    assert want.fitness.sum() > 0        # some contact: the comparison is not all zeros
    np.testing.assert_array_equal(got.fitness, want.fitness)          # econet by econet
    for field in ("fitness", "success", "latency", "separations"):     # trial by trial
        np.testing.assert_array_equal(getattr(got.measures, field),
                                      getattr(want.measures, field))
    np.testing.assert_array_equal(got.parents, want.parents)
    assert sup.repeats == 0


def test_lockstep_under_load_no_cycle_skipped_or_repeated(graph, ros):
    """A busy process hogs a core while the graph runs trials: every trial's sensor
    cycles still arrive exactly once each, in order."""
    retina = []
    sensed = graph.create_subscription(
        Retina, "retina", lambda m: retina.append((m.trial, m.cycle)), common.LOCKSTEP_QOS)
    spin_until(ros, lambda: sensed.get_publisher_count() > 0, what="the world's retina")
    reset = graph.create_client(ResetTrials, "reset_trials")
    weights = graph.create_client(SetWeights, "set_weights")
    k = InProcessEvaluator(small_config()).n_weights
    call(ros, weights, SetWeights.Request(
        n_envs=50, weights_per_network=k,
        weights=common.f64(np.random.default_rng(1).uniform(-10, 10, (50, k)))))
    burners = [subprocess.Popen([sys.executable, "-c", "while True: pass"])
               for _ in range(1)]
    try:
        trials = []
        for seed in range(3):
            reply = call(ros, reset, ResetTrials.Request(n_envs=50, cycles=80, seed=seed))
            assert reply.success
            trials.append(reply.trial)
            spin_until(ros, lambda: (reply.trial, 80) in retina, timeout=90,
                       what="the trial's last cycle")
    finally:
        for burner in burners:
            burner.kill()
            burner.wait()
    for trial in trials:
        assert [c for t, c in retina if t == trial] == list(range(81))


def run_in_process(config, out):
    run_condition(config, 1, 3, out, progress=False)
    return out / "run-01"


def supervisor_params(out, condition="normal", generations=3, **extra):
    params = {**SMALL, "condition": condition, "generations": generations, "seed": 3,
              "out": str(out), **extra}
    return [f"{k}:={v}" for k, v in params.items()]


def test_evolution_through_graph_writes_the_in_process_result_folder(graph, procs, ros,
                                                                        tmp_path):
    for client in list(graph.clients):      # the earlier tests' service clients: a supervisor
        graph.destroy_client(client)        # waits while another client of its services is listed
    progress = []
    graph.create_subscription(EvolutionProgress, "progress", progress.append,
                              common.QOS["progress"])
    # Three small generations take a second or two; under load this test's node may discover
    # the supervisor only later, so the supervisor lingers long enough for its progress history
    # (transient local) to reach a late monitor.
    proc, log = procs.start("supervisor", "/g",
                            *supervisor_params(tmp_path / "graph", linger_sec=5.0))
    spin_until(ros, lambda: len(progress) == 3 or proc.poll() is not None, timeout=90,
               what="progress from the supervisor")
    spin_until(ros, lambda: proc.poll() is not None, timeout=90, what="the supervisor")
    assert proc.returncode == 0, log.read_text()
    want = run_in_process(small_config(generations=3), tmp_path / "inproc")
    got = tmp_path / "graph" / "run-01"
    for name in FILES:
        assert (got / name).read_bytes() == (want / name).read_bytes(), name
    assert len(progress) == 3
    assert [m.generation for m in progress] == [0, 1, 2]
    assert "generation 3/3" in log.read_text()


def test_supervisor_survives_a_vanished_controller(procs, ros, tmp_path):
    """The controller is killed mid-run: the supervisor says so, waits, and when a controller
    returns it tests the interrupted generation again; the folder matches the in-process one."""
    ns = "/crash"
    procs.start("world", ns)
    controller, _ = procs.start("controller", ns)
    sup, log = procs.start("supervisor", ns, *supervisor_params(
        tmp_path / "graph", generations=40, stall_timeout_sec=1.0, service_timeout_sec=2.0))
    spin_until(ros, lambda: "generation 1/40" in log.read_text(), timeout=60,
               what="the first generation")
    procs.kill(controller, signal.SIGKILL)
    spin_until(ros, lambda: "testing the generation again" in log.read_text(), timeout=30,
               what="the supervisor to notice")
    assert sup.poll() is None
    # The controller returns. Once in four full suites here DDS never discovered a controller
    # restarted while its killed predecessor was still listed (no node heard it, on any topic
    # or service, for 90 s), so a controller that is not heard within a minute is restarted
    # again, up to three times; the supervisor's part (wait, then test the generation again)
    # is the same either way.
    def progress():
        return log.read_text().count("/40:")          # "generation G/40: best ..." lines
    for _ in range(3):
        controller, _ = procs.start("controller", ns)
        before, deadline = progress(), time.monotonic() + 60      # the old lease is 20 s
        while sup.poll() is None and progress() == before and time.monotonic() < deadline:
            time.sleep(0.5)
        if sup.poll() is not None or progress() > before:
            break
        procs.kill(controller, signal.SIGKILL)
    spin_until(ros, lambda: sup.poll() is not None, timeout=90, what="the supervisor")
    assert sup.returncode == 0, log.read_text()
    want = run_in_process(small_config(generations=40), tmp_path / "inproc")
    for name in FILES:
        assert (tmp_path / "graph" / "run-01" / name).read_bytes() == \
            (want / name).read_bytes(), name


def test_bad_parameter_is_one_line_error(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "econet_ros.nodes.controller_node",
                           "--ros-args", "-p", "controller:=five-layer"], cwd=REPO,
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2
    assert proc.stderr.strip().splitlines() == [
        "controller_node: error: unknown controller 'five-layer': not a registered name "
        "(normal, random, reacher, three-layer) and not module:Class"]


def sensor_probe(ros, namespace, on_command):
    """A node in NAMESPACE that plays the world to a controller there: ON_COMMAND hears its
    commands, and send(cycle, retina_values=8) publishes one environment's three sensor
    messages of trial 1 (RETINA_VALUES activations: 8 is consistent)."""
    node = make_node(ros, f"{namespace.strip('/')}_probe", namespace)
    answers = node.create_subscription(MuscleCommand, "muscle_command", on_command,
                                       common.LOCKSTEP_QOS)
    pubs = {name: node.create_publisher(t, name, common.LOCKSTEP_QOS)
            for name, t in (("retina", Retina), ("proprioception", Proprioception),
                            ("touch", Touch))}
    spin_until(ros, lambda: all(p.get_subscription_count() for p in pubs.values())
               and answers.get_publisher_count(), what="the controller, matched both ways")

    def send(cycle, retina_values=8):
        head = dict(trial=1, cycle=cycle, n_envs=1)
        pubs["touch"].publish(Touch(**head, contact=array.array("B", [0])))
        pubs["proprioception"].publish(Proprioception(**head, stretch=common.f64([0.5] * 4)))
        pubs["retina"].publish(Retina(**head, units_per_env=8,
                                      activation=common.f64([0.0] * retina_values),
                                      fixated=array.array("B", [0])))
    return node, send


def test_controller_ignores_sensors_of_inconsistent_size(procs, ros):
    """Sensor arrays that do not match their n_envs get a log line and no command; the
    controller keeps serving and answers the next consistent cycle."""
    _, log = procs.start("controller", "/badsense")
    commands = []
    node, send = sensor_probe(ros, "/badsense", commands.append)

    send(0, 7)                                   # one retina value short
    # Consistent cycles follow, one a second until one is answered: seeing the controller's
    # command publisher does not mean it has seen this node's subscription yet.
    cycle = 0
    while not commands and cycle < 30:
        cycle += 1
        send(cycle, 8)
        deadline = time.monotonic() + 1.0
        while not commands and time.monotonic() < deadline:
            ros.spin_once(timeout_sec=0.05)
    assert commands, "no command for any consistent cycle within 30 s"
    assert all(c.trial == 1 and 1 <= c.cycle <= cycle for c in commands)
    assert "ignored trial 1 cycle 0: retina.activation has 7 values, expected 8 for n_envs=1" \
        in log.read_text()


def test_a_cycle_sent_again_gets_the_same_command_and_random_movement_does_not_move_on(procs,
                                                                                       ros):
    """The world sends a cycle's sensors again when no command came for RESEND_SEC (a busy
    machine): the controller answers with the command it sent for that cycle, without acting
    again, so random movement's generator is where the in-process engine's is on the next
    cycle (acting twice drew one command ahead: the graph's random fitness then parted from the
    in-process one, docs/reliability.md)."""
    procs.start("controller", "/resent", "controller:=random")
    heard = {}                               # cycle -> every command heard for it
    node, send = sensor_probe(ros, "/resent", lambda m: heard.setdefault(m.cycle, []).append(
        np.array(m.activation)))
    k = RandomMovement(1, Config()).n_params      # a net it carries but does not move by
    reply = call(ros, node.create_client(SetWeights, "set_weights"), SetWeights.Request(
        n_envs=1, weights_per_network=k, weights=common.f64([0.0] * k), noise_seed=7))
    assert reply.success, reply.message

    def answered(cycle, times):
        for _ in range(30):                  # once a second, as the world sends a cycle again
            send(cycle)
            deadline = time.monotonic() + 1.0
            while len(heard.get(cycle, ())) < times and time.monotonic() < deadline:
                ros.spin_once(timeout_sec=0.05)
            if len(heard.get(cycle, ())) >= times:
                return
        pytest.fail(f"cycle {cycle} answered {len(heard.get(cycle, ()))} times, not {times}")

    answered(0, 2)                           # cycle 0 sent at least twice, answered twice
    answered(1, 1)
    draws = np.random.default_rng(7).random((2, 5))    # RandomMovement with noise seed 7
    for command in heard[0]:
        np.testing.assert_array_equal(command, draws[0])
    np.testing.assert_array_equal(heard[1][0], draws[1])

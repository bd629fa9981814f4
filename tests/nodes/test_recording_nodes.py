"""Recording trials as rosbag2 bags through the running graph (supervisor and recorder node), read
back with the rosbags reader and with rclpy's deserializer; an interrupted recording; a recorder
that waits for its publishers and keeps every trial_start; a killed recorder's bag repaired."""
import os
import signal
import time

import numpy as np
import pytest

from econet_ros.cli import main
from econet_ros.recording import bags

from graph_helpers import call, ros_session, spin_until

pytestmark = pytest.mark.ros       # every test here starts ROS nodes

SMALL = {"population": 6, "parents": 2, "trials": 3, "cycles": 40}


@pytest.fixture(scope="module")
def ros(tmp_path_factory):
    yield from ros_session(tmp_path_factory, 200 + os.getpid() % 15, "bag")


def test_supervisor_records_the_best_econet_through_the_graph(ros, tmp_path, capsys):
    rclpy, executor, procs = ros
    ns, out = "/bagrec", tmp_path / "graph"
    procs.start("world", ns)
    procs.start("controller", ns)
    params = {**SMALL, "generations": 2, "seed": 5, "out": str(out), "record_every": 1}
    sup, log = procs.start("supervisor", ns, *[f"{k}:={v}" for k, v in params.items()])
    assert sup.wait(120) == 0, log.read_text()
    fitness = np.load(out / "run-01" / "fitness.npy")
    cycles, trials = SMALL["cycles"], SMALL["trials"]
    assert sorted(p.name for p in (out / "bags" / "run-01").iterdir()) == ["gen-0000",
                                                                           "gen-0001"]
    for generation in (0, 1):
        path = out / "bags" / "run-01" / f"gen-{generation:04d}"
        assert (path / "metadata.yaml").is_file() and (path / f"{path.name}.mcap").is_file()
        metadata = (path / "metadata.yaml").read_text()
        assert "durability: transient_local" in metadata     # trial_start's offered QoS
        bag = bags.read_bag(path)                           # the rosbags reader
        assert [bag.count(t) for t in ("trial_start", "retina", "proprioception", "touch",
                                       "muscle_command")] == [1, cycles + 1, cycles + 1,
                                                              cycles + 1, cycles]
        assert bag.count("markers") >= 1 and bag.count("joint_states") >= 1
        (trial,) = bag.trials
        assert trial.complete and trial.n_envs == trials
        measures = trial.measures()
        best = int(bag.custom["econet.econet"])
        scored = [int(x) for x in bag.custom["econet.scored_fitness"].strip("[]").split(",")]
        assert list(measures.fitness) == scored              # what the supervisor scored
        assert measures.fitness.sum() == fitness[generation].max() == fitness[generation, best]
        assert bags.replay(trial).mismatch is None

        check_with_rclpy(path, trial, scored, cycles)

    status = main(["bag", "measures", str(path)])
    text = capsys.readouterr().out
    assert status == 0 and f"fitness {int(fitness[1].max())}" in text
    assert main(["bag", "replay", str(path)]) == 0
    assert "replay: identical" in capsys.readouterr().out
    assert main(["bag", "render", str(path), "--env", "1", "--out", str(tmp_path / "pics")]) == 0
    pictures = sorted(p.suffix for p in (tmp_path / "pics").iterdir())
    assert pictures == [".gif", ".png"]


def check_with_rclpy(path, trial, scored, cycles):
    """The bag's messages through rclpy's own deserializer: the trial_start first (no display
    picture of an earlier trial before it), and the values the rosbags reader gave."""
    from econet_msgs.msg import MuscleCommand, Retina, Touch, TrialStart
    from rclpy.serialization import deserialize_message
    from rosbags.rosbag2 import Reader

    classes = {"trial_start": TrialStart, "retina": Retina, "touch": Touch,
               "muscle_command": MuscleCommand}
    seen = {k: [] for k in classes}
    order = []
    with Reader(path) as reader:
        for connection, _, raw in reader.messages():
            short = connection.topic.rsplit("/", 1)[-1]
            order.append(short)
            if short in classes:
                seen[short].append(deserialize_message(raw, classes[short]))
    assert order[0] == "trial_start"
    (start,) = seen["trial_start"]
    assert start.n_envs == trial.n_envs and start.lockstep and start.trial == trial.trial
    np.testing.assert_array_equal(np.asarray(start.object_xy).reshape(-1, 2),
                                  trial.setup.object_xy)
    assert [m.cycle for m in seen["touch"]] == list(range(cycles + 1))
    contact = np.array([np.frombuffer(m.contact, np.uint8) for m in seen["touch"][1:]])
    assert list(contact.sum(axis=0)) == scored
    assert np.array_equal(np.asarray(seen["retina"][7].activation).reshape(trial.n_envs, -1),
                          trial.vision[7])


def test_interrupted_recording_is_still_a_readable_bag(ros, tmp_path):
    rclpy, executor, procs = ros
    from econet_msgs.msg import Touch
    from econet_msgs.srv import ResetTrials, SetWeights

    from econet_ros.nodes import graph as common

    ns, path = "/bagint", tmp_path / "interrupted"
    procs.start("world", ns)
    procs.start("controller", ns, "controller:=reacher")
    recorder, log = procs.start("recorder", ns, f"out:={path}")
    node = rclpy.create_node("int_probe", namespace=ns)
    executor.add_node(node)
    heard = []
    node.create_subscription(Touch, "touch", lambda m: heard.append(m.cycle),
                             common.LOCKSTEP_QOS)
    spin_until(executor, lambda: "recording trial_start" in log.read_text(),
               what="the recorder to say it is recording")
    call(executor, node.create_client(SetWeights, "set_weights"),
         SetWeights.Request(n_envs=4, weights_per_network=0))
    reply = call(executor, node.create_client(ResetTrials, "reset_trials"),
                 ResetTrials.Request(n_envs=4, cycles=100000, seed=2))
    assert reply.success
    spin_until(executor, lambda: len(heard) > 150, timeout=60, what="150 cycles")
    os.killpg(recorder.pid, signal.SIGTERM)                  # as a service manager stops it
    assert recorder.wait(20) == 0, log.read_text()
    assert (path / "metadata.yaml").is_file()
    bag = bags.read_bag(path)
    (trial,) = bag.trials
    assert not trial.complete and trial.cycles == 100000
    # everything before the signal: a live recorder takes every message as it comes and misses
    # nothing; only the cycles after the signal are absent (no gaps before them)
    assert bag.count("touch") >= 100 and bag.count("muscle_command") >= 100
    assert not trial.have_sensors[trial.heard_cycles + 1:].any()
    commands = int(np.argmin(trial.have_command))
    assert not trial.have_command[commands:].any() and commands >= trial.heard_cycles - 1
    result = bags.replay(trial)
    assert result.mismatch is None and result.checked == min(
        trial.heard_cycles, int(np.argmin(trial.have_command)))


def test_recorder_says_recording_once_matched_and_keeps_every_trial_start(ros, tmp_path):
    """A recorder started before the graph waits for publishers; once it says "recording", a
    trial started at once is in the bag from cycle 0, and so is every one of twenty resets in
    quick succession (each with its trial_start: none is hidden from bag info)."""
    rclpy, executor, procs = ros
    from econet_msgs.msg import Touch
    from econet_msgs.srv import ResetTrials, SetWeights

    from econet_ros.nodes import graph as common

    ns, path = "/bagmatch", tmp_path / "matched"
    recorder, log = procs.start("recorder", ns, f"out:={path}")
    node = rclpy.create_node("match_probe", namespace=ns)
    executor.add_node(node)
    spin_until(executor, lambda: "waiting for publishers of" in log.read_text(),
               what="the recorder to start waiting")
    assert "recording trial_start" not in log.read_text()
    heard = []
    touch = node.create_subscription(Touch, "touch", lambda m: heard.append((m.trial, m.cycle)),
                                     common.LOCKSTEP_QOS)
    procs.start("world", ns)
    procs.start("controller", ns, "controller:=reacher")
    spin_until(executor, lambda: "recording trial_start" in log.read_text()
               and touch.get_publisher_count() > 0,
               what="the recorder to say it is recording, and the probe to hear the world")
    call(executor, node.create_client(SetWeights, "set_weights"),
         SetWeights.Request(n_envs=3, weights_per_network=0))
    reset = node.create_client(ResetTrials, "reset_trials")
    first = call(executor, reset, ResetTrials.Request(n_envs=3, cycles=30, seed=1)).trial
    spin_until(executor, lambda: (first, 30) in heard, what="the first trial")
    quick = [call(executor, reset, ResetTrials.Request(n_envs=3, cycles=2, seed=k)).trial
             for k in range(20)]
    spin_until(executor, lambda: (quick[-1], 2) in heard, what="the last quick trial")
    os.killpg(recorder.pid, signal.SIGINT)
    assert recorder.wait(20) == 0, log.read_text()
    bag = bags.read_bag(path)
    assert bag.unstarted == {}
    assert [t.trial for t in bag.trials] == [first, *quick]
    assert bag.trials[0].complete and bags.replay(bag.trials[0]).mismatch is None


# Reruns on failure while the one miss in a fresh clone's suite is unexplained (docs/
# reliability.md, "Open"); the world's pause now rules out a recorder lagging the stream.
@pytest.mark.flaky(reruns=2)
def test_killed_recorder_loses_at_most_the_last_second_and_repairs(ros, tmp_path, capsys):
    """SIGKILL leaves no metadata.yaml and no MCAP footer; bag info says how to recover, and
    `econet bag repair` recovers every cycle the recorder had a second to put on disk. The
    world is paused (SIGSTOP) a second and a half before the kill, so that what the recorder
    has received is all that was published: a recorder lagging behind a busy machine's stream
    once made a wall-clock bound on the stream itself miss (docs/reliability.md)."""
    rclpy, executor, procs = ros
    from econet_msgs.msg import Touch

    from econet_ros.nodes import graph as common

    ns, path = "/bagkill", tmp_path / "killed"
    world, _ = procs.start("world", ns, "mode:=free", "rate_hz:=50", "n_envs:=4",
                           "trial_cycles:=0")
    recorder, log = procs.start("recorder", ns, f"out:={path}", "topics:=trial_start,retina,"
                                "proprioception,touch,joint_states,markers")
    node = rclpy.create_node("kill_probe", namespace=ns)
    executor.add_node(node)
    heard = []
    node.create_subscription(Touch, "touch", lambda m: heard.append(
        (time.monotonic(), m.trial, m.cycle)), common.LOCKSTEP_QOS)
    spin_until(executor, lambda: "recording trial_start" in log.read_text(),
               what="the recorder to say it is recording")
    since = time.monotonic()
    spin_until(executor, lambda: sum(t > since for t, _, _ in heard) > 150,
               what="three seconds of cycles since the recorder said it is recording")
    os.kill(world.pid, signal.SIGSTOP)
    paused_at = time.monotonic()
    while time.monotonic() < paused_at + 1.5:
        executor.spin_once(timeout_sec=0.05)
    os.killpg(recorder.pid, signal.SIGKILL)
    recorder.wait(10)
    os.kill(world.pid, signal.SIGCONT)
    assert not (path / "metadata.yaml").exists()
    assert main(["bag", "info", str(path)]) == 2
    assert f"econet bag repair {path} recovers it" in capsys.readouterr().err
    assert main(["bag", "repair", str(path)]) == 0
    assert "repaired:" in capsys.readouterr().out
    repaired = bags.read_bag(tmp_path / "killed-repaired")
    (trial,) = repaired.trials
    recorded = set(np.flatnonzero(trial.have_sensors))
    # the last cycle heard may have been paused between its three sensor messages
    last = max(cycle for _, _, cycle in heard)
    wanted = {cycle for t, _, cycle in heard if since < t < paused_at and cycle < last}
    assert len(wanted) > 50 and wanted <= recorded

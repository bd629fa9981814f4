#!/usr/bin/env python3
"""Benchmark the node graph against its floor, in one run:

  1. in-process: the core's InProcessEvaluator.test_generation for one generation (no ROS);
  2. bare round trip: ping-pong of a tiny message between two processes (rclpy, same executor
     as the nodes), the cost of one lockstep cycle that does no work;
  3. messaging alone: the graph's four lockstep messages of a paper-size cycle (touch,
     proprioception, retina, muscle command: the same bytes) passed between a stand-in world and
     a stand-in controller that compute nothing, with this process listening to touch as the
     supervisor does; what the message design costs before any work is done;
  4. graph: the same generation through world_node and controller_node, each in its own
     process, driven by this process as the supervisor (SupervisorNode.test_generation);
  4b. with --apart-env 'NAME=VALUE ...' (repeatable): the graph again with world_node and
     controller_node started with those environment variables, then the default once more;
  5. composed, in a child process that starts as graph_node does: messaging alone between a
     stand-in world and controller that are nodes of that one process, and the generation
     through a WorldNode, ControllerNode and SupervisorNode of that process on one executor;
and prints how far the graph is above its floor, floor = in-process + messaging alone (the
model's work plus the messages, neither of which the graph can avoid), against the target of
1.3 x the floor, and the projected time of a whole run; then where a cycle of the graph goes:
each part of the nodes' per-cycle work timed in a hot loop here (the same calls the nodes
make, paper size), against the graph's cycle and messaging alone; then the composed graph
against its own floor (in-process + messaging alone within one process) and against the
in-process generation (target 1.5x). The load average is printed at the start and the end.

Every process it starts is waited for until it says it is ready (the nodes log "... ready" once
their kernels are compiled, minutes on a cold numba cache), not for a fixed time.

Run after the set-up:  . scripts/env.sh && flock /tmp/econet-bench.lock python scripts/bench/bench_graph.py [--generations 5]
Defaults are paper size: 100 econets x 20 trials (2000 environments) x 100 cycles.
"""
from __future__ import annotations

import argparse
import collections
import json
import os
import random
import signal
import statistics
import subprocess
import sys
import threading
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
# A process that has not said it is ready after this long has failed: compiling every kernel
# on a cold numba cache takes 2-3 minutes on a busy two-core machine.
READY_TIMEOUT_SEC = 900.0
READY = "bench ready"       # what the echo and the stand-ins print once they are
RESEND_SEC = 0.5            # the stand-in world: no command for this long, send again
COMPOSED = "--composed-child"   # runs composed_main (the composed measurements)


def echo_main() -> int:
    """The far end of the ping-pong: answer every ping on `ping` with a pong on `pong`."""
    import rclpy
    from econet_msgs.msg import Touch
    from econet_ros.nodes import graph as common
    from econet_ros.nodes.runner import make_executor, spin

    rclpy.init()
    node = rclpy.create_node("bench_echo")
    pub = node.create_publisher(Touch, "pong", common.LOCKSTEP_QOS)
    node.create_subscription(Touch, "ping", pub.publish, common.LOCKSTEP_QOS)
    executor = make_executor()
    print(READY, flush=True)
    try:
        spin(node, executor)
    except KeyboardInterrupt:
        pass
    return 0


def paper_cycle(n_envs: int):
    """A world of n_envs environments at the start of a trial, its sensor messages written
    (lockstep_wire), and a muscle command for it."""
    import numpy as np
    from econet_ros.config import Config
    from econet_ros.nodes.lockstep_wire import CommandMessage, SensorMessages
    from econet_ros.world import N_MOTOR, World, sample_setups

    model = Config().model
    world = World(n_envs, model)
    world.reset(sample_setups(np.random.default_rng(0), n_envs, model))
    wire = SensorMessages(n_envs, model.visual_units)
    wire.write(world, 1, False)
    motor = np.full((n_envs, N_MOTOR), 0.5)
    return world, wire, CommandMessage(n_envs), motor


def paper_cycle_messages(n_envs: int) -> tuple[dict[str, bytes], bytes]:
    """One cycle's serialized sensor messages and muscle command, at their real sizes."""
    _, wire, command, motor = paper_cycle(n_envs)
    return wire.encoded(), command.encode(1, 0, motor)


def stand_in(node, role: str, n_envs: int, running=lambda: True) -> None:
    """Make ``node`` a world or controller that only passes messages: the world answers every
    command with the same three sensor messages, the controller answers every complete set of
    three with the same command. The world starts their chain of messages, and starts it again
    whenever no command came for RESEND_SEC (as world_node sends a cycle again: a message sent
    before both sides of a topic have matched is lost); all while running()."""
    from econet_ros.nodes import graph as common
    from econet_ros.topics import COMMAND, SENSORS

    sensors, command = paper_cycle_messages(n_envs)
    if role == "world":
        pubs = {part: common.publisher(node, part) for part in SENSORS}
        sent = [0.0]

        def publish() -> None:
            sent[0] = time.monotonic()
            for part in SENSORS:
                pubs[part].publish(sensors[part])

        def start_again() -> None:
            if running() and time.monotonic() - sent[0] > RESEND_SEC:
                publish()
        common.subscription(node, COMMAND, lambda _data: running() and publish(), raw=True)
        node.create_timer(RESEND_SEC / 5, start_again)
        return
    pub = common.publisher(node, COMMAND)
    heard = dict.fromkeys(SENSORS, 0)
    answered = [0]

    def on_part(part: str) -> None:
        heard[part] += 1
        if min(heard.values()) > answered[0]:
            answered[0] += 1
            pub.publish(command)
    for part in SENSORS:
        common.subscription(node, part, lambda _data, part=part: on_part(part), raw=True)


def stand_in_main(role: str, n_envs: int) -> int:
    """A stand-in world or controller (stand_in) as a process of its own."""
    import rclpy
    from econet_ros.nodes.runner import make_executor, spin

    rclpy.init()
    node = rclpy.create_node(f"bench_{role}")
    stand_in(node, role, n_envs)
    print(READY, flush=True)
    try:
        spin(node, make_executor())
    except KeyboardInterrupt:
        pass
    return 0


def messaging_alone(executor, node, n: int) -> float:
    """Mean seconds per cycle of the stand-in world and controller (n cycles after 50 warm-up
    ones), heard on touch as the supervisor hears them."""
    from econet_ros.nodes import graph as common

    touches = []
    listen = common.subscription(node, "touch", lambda _data: touches.append(
        time.perf_counter()), raw=True)
    spin_until(executor, lambda: len(touches) > n + 50,
               f"{n + 50} cycles of the stand-in world and controller")
    node.destroy_subscription(listen)
    return (touches[n + 50] - touches[50]) / n


def cycle_parts(args, executor, node, n: int = 300) -> list[tuple[str, float, bool]]:
    """(part, median seconds, whether messaging alone does it too) for each part of the
    nodes' per-cycle work, timed here in a hot loop, paper size: the calls world_node and
    controller_node make, in their order, publishing to topics of their own."""
    import numpy as np
    from econet_ros.evolution import genome_weights, initial_genomes
    from econet_ros.nodes import graph as common
    from econet_ros.plugins import resolve
    from econet_ros.topics import COMMAND, SENSORS, observation_from_fields, sensor_problem

    n_envs = args.population * args.trials
    world, wire, command, motor = paper_cycle(n_envs)
    controller = resolve(args.config.evolution.condition)(n_envs, args.config)
    controller.load(genome_weights(args.config, initial_genomes(
        args.config, controller.n_params, 1, 1)))
    pubs = {part: node.create_publisher(common.message_class(part), f"bench_parts_{part}",
                                        common.qos(part)) for part in (*SENSORS, COMMAND)}
    subs = [node.create_subscription(common.message_class(part), f"bench_parts_{part}",
                                     lambda _data: None, common.qos(part), raw=True)
            for part in pubs]
    spin_until(executor, lambda: all(pub.get_subscription_count() for pub in pubs.values()),
               "the bench's own subscriptions to match")

    def timed(call, publishes: bool = False) -> float:
        times = []
        for i in range(n + 20):                 # the first 20 warm up
            t0 = time.perf_counter()
            call()
            times.append(time.perf_counter() - t0)
            if publishes:
                executor.spin_once(timeout_sec=0)
        return statistics.median(times[20:])

    sensors = wire.encoded()
    decoded = {part: common.decode(node, part, sensors[part]) for part in SENSORS}
    obs = observation_from_fields(decoded)
    outputs = controller.act(obs)
    data = command.encode(1, 0, outputs)
    units = args.config.model.visual_units
    parts = [
        ("world: decode the command", timed(lambda: common.decode(node, COMMAND, data)), False),
        ("world: step and write the three messages (one kernel)",
         timed(lambda: wire.step(world, motor, 1, False)), False),
        ("      (World.step alone, for comparison)", timed(lambda: world.step(motor)), None),
        ("world: the messages as bytes for rclpy", timed(wire.encoded), True),
        ("world: publish the three", timed(lambda: [pubs[part].publish(sensors[part])
                                                    for part in SENSORS], True), True),
        ("controller: decode the three (views)",
         timed(lambda: [common.decode(node, part, sensors[part]) for part in SENSORS]), False),
        ("controller: check the three", timed(lambda: [sensor_problem(
            part, decoded[part], n_envs, units) for part in SENSORS]), False),
        ("controller: observation from the messages",
         timed(lambda: observation_from_fields(decoded)), False),
        ("controller: forward (act)", timed(lambda: controller.act(obs)), False),
        ("controller: write the command", timed(lambda: command.encode(1, 0, outputs)), True),
        ("controller: publish it", timed(lambda: pubs[COMMAND].publish(data), True), True),
    ]
    for sub in subs:
        node.destroy_subscription(sub)
    for pub in pubs.values():
        node.destroy_publisher(pub)
    return parts


def start(args: list[str], ready: str, env: dict | None = None) -> subprocess.Popen:
    """Start a Python process (with ``env`` added to the environment) and wait until a line of
    its output contains ``ready`` (its output is read on, and its last lines are kept for the
    error message if it fails)."""
    proc = subprocess.Popen([sys.executable, *args], cwd=REPO, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, start_new_session=True,
                            env={**os.environ, **(env or {})})
    said_ready, tail = threading.Event(), collections.deque(maxlen=10)

    def read() -> None:
        for line in proc.stdout:
            tail.append(line.rstrip())
            if ready in line:
                said_ready.set()
    threading.Thread(target=read, daemon=True).start()
    deadline = time.monotonic() + READY_TIMEOUT_SEC
    while not said_ready.wait(0.2):
        if proc.poll() is not None or time.monotonic() > deadline:
            what = "exited" if proc.poll() is not None else \
                f"did not say it within {READY_TIMEOUT_SEC:g} s"
            stop([proc])
            raise SystemExit(f"bench_graph: error: waited for {' '.join(args)} to say "
                             f"'{ready}' (once its kernels are compiled); it {what}; its last "
                             "lines:\n  " + "\n  ".join(tail))
    return proc


def stop(procs: list[subprocess.Popen]) -> None:
    for proc in procs:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGINT)
    for proc in procs:
        try:
            proc.wait(5)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()


def spin_until(executor, done, what: str, timeout: float = 60.0) -> None:
    """Spin until done(); the processes are ready by now, so this waits for DDS discovery or
    for messages, never for a compilation."""
    deadline = time.monotonic() + timeout
    while not done():
        if time.monotonic() > deadline:
            raise SystemExit(f"bench_graph: error: waited {timeout:g} s for {what}")
        executor.spin_once(timeout_sec=0.05)


def round_trip(executor, node, n: int) -> list[float]:
    from econet_msgs.msg import Touch
    from econet_ros.nodes import graph as common

    got = []
    pub = node.create_publisher(Touch, "ping", common.LOCKSTEP_QOS)
    node.create_subscription(Touch, "pong", got.append, common.LOCKSTEP_QOS)
    spin_until(executor, lambda: pub.get_subscription_count() > 0
               and node.count_publishers("pong") > 0, "the echo to match")
    times = []
    for i in range(n + 50):              # the first 50 warm up
        t0 = time.perf_counter()
        pub.publish(Touch(cycle=i))
        spin_until(executor, lambda: len(got) > i, f"pong {i}")
        times.append(time.perf_counter() - t0)
    return times[50:]


def parse_args() -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--generations", type=int, default=5,
                        help="generations to time in-process and through the graph (default 5)")
    parser.add_argument("--population", type=int, default=100, help="econets (default 100)")
    parser.add_argument("--parents", type=int, default=20, help="parents kept (default 20)")
    parser.add_argument("--trials", type=int, default=20,
                        help="trials per econet (default 20)")
    parser.add_argument("--cycles", type=int, default=100, help="cycles per trial (default 100)")
    parser.add_argument("--round-trips", type=int, default=2000,
                        help="round trips, and cycles of messaging alone, to time (default 2000)")
    parser.add_argument("--apart-env", action="append", default=[], metavar="'NAME=VALUE ...'",
                        help="also time the three-process graph with world and controller "
                             "started with these environment variables (repeatable), e.g. "
                             "NUMBA_THREADING_LAYER=workqueue")
    parser.add_argument("--composed-env", action="append", default=[],
                        metavar="'NAME=VALUE ...'",
                        help="also time the composed graph in a process started with these "
                             "environment variables (repeatable)")
    parser.add_argument("--run-generations", type=int, default=200,
                        help="generations of the projected whole run (default: the paper's 200)")
    args = parser.parse_args()
    for name in ("generations", "round_trips", "run_generations"):
        if getattr(args, name) < 1:
            parser.error(f"--{name.replace('_', '-')} must be at least 1, "
                         f"got {getattr(args, name)}")
    from econet_ros.config import Config, ConfigError

    args.sizes = dict(population=args.population, parents=args.parents, trials=args.trials,
                      cycles=args.cycles)
    try:
        args.config = Config().replace(**{f"evolution.{k}": v
                                          for k, v in args.sizes.items()}).validated()
    except ConfigError as error:
        parser.error(str(error))
    return args


def in_process(args) -> tuple[float, list, object]:
    """Median seconds of an in-process generation, each generation's fitness, the genomes."""
    from econet_ros.evolution import InProcessEvaluator, initial_genomes

    evaluator = InProcessEvaluator(args.config)
    genomes = initial_genomes(args.config, evaluator.n_weights, 1, 1)
    evaluator.test_generation(genomes, 1, 1, 0)          # warm up (numba)
    times, fitness = [], []
    for g in range(args.generations):
        t0 = time.perf_counter()
        fitness.append(evaluator.test_generation(genomes, 1, 1, g).fitness)
        times.append(time.perf_counter() - t0)
    return statistics.median(times), fitness, genomes


def through_graph(args, sup, genomes, expected) -> float:
    """Median seconds of a generation through the world and controller nodes (``sup``, a
    SupervisorNode of this process, as the supervisor), each checked against the in-process
    fitness."""
    import numpy as np

    sup.evaluator.wait_for_graph()
    sup.evaluator.test_generation(genomes, 1, 1, 0)    # warm up (first big messages)
    times = []
    for g in range(args.generations):
        t0 = time.perf_counter()
        result = sup.evaluator.test_generation(genomes, 1, 1, g)
        times.append(time.perf_counter() - t0)
        if not np.array_equal(result.fitness, expected[g]):
            raise SystemExit(f"bench_graph: error: generation {g}: graph fitness differs "
                             "from the in-process engine")
    return statistics.median(times)


def supervisor(executor):
    """This process as the supervisor (parameters from rclpy.init's global arguments)."""
    from econet_ros.nodes.supervisor_node import SupervisorNode

    sup = SupervisorNode()
    sup.evaluator.executor = executor
    executor.add_node(sup)
    return sup


def apart(args, sup, genomes, expected, env: dict) -> float:
    """through_graph with world_node and controller_node as processes started with ``env``."""
    procs = [start(["-m", f"econet_ros.nodes.{role}_node"], f"{role} ready", env)
             for role in ("world", "controller")]
    try:
        return through_graph(args, sup, genomes, expected)
    finally:
        stop(procs)


def composed_main() -> int:
    """The composed measurements, in a process of their own that starts as graph_node does
    (econet_ros.nodes imported first: OpenMP workers that sleep): messaging alone between a
    stand-in world and controller that are nodes of this process, then the generation through
    a WorldNode, a ControllerNode and a SupervisorNode of this process, all on one executor.
    Prints them as one JSON line."""
    import econet_ros.nodes  # noqa: F401 - before any kernel runs, as in graph_node
    import rclpy
    from econet_ros.nodes.controller_node import ControllerNode
    from econet_ros.nodes.runner import make_executor
    from econet_ros.nodes.world_node import WorldNode

    sys.argv.remove(COMPOSED)
    args = parse_args()
    t_in, expected, genomes = in_process(args)
    rclpy.init(args=init_args(args))
    executor = make_executor()
    node = rclpy.create_node("bench_ping")
    executor.add_node(node)
    stand_ins, running = [], threading.Event()
    running.set()
    for role in ("world", "controller"):
        stand_ins.append(rclpy.create_node(f"bench_{role}"))
        stand_in(stand_ins[-1], role, args.population * args.trials, running.is_set)
        executor.add_node(stand_ins[-1])
    t_msg = messaging_alone(executor, node, args.round_trips)
    running.clear()                               # their chain of messages ends
    deadline = time.monotonic() + 0.5
    while time.monotonic() < deadline:
        executor.spin_once(timeout_sec=0.05)
    for stand_in_node in stand_ins:
        executor.remove_node(stand_in_node)
        stand_in_node.destroy_node()
    for make in (WorldNode, ControllerNode):      # their own defaults, not the supervisor's
        executor.add_node(make(use_global_arguments=False))
    t_graph = through_graph(args, supervisor(executor), genomes, expected)
    print(json.dumps({"in_process": t_in, "messaging": t_msg, "graph": t_graph}), flush=True)
    rclpy.try_shutdown()
    return 0


def composed(env: dict) -> dict:
    """composed_main's figures (seconds), run as a child process with ``env`` added to the
    environment."""
    domain = str(int(os.environ["ROS_DOMAIN_ID"]) % 200 + 1)    # away from what ran here
    proc = subprocess.run([sys.executable, __file__, COMPOSED, *sys.argv[1:]], cwd=REPO,
                          capture_output=True, text=True, timeout=READY_TIMEOUT_SEC,
                          env={**os.environ, **env, "ROS_DOMAIN_ID": domain})
    if proc.returncode != 0:
        raise SystemExit(f"bench_graph: error: the composed measurement failed:\n"
                         f"{proc.stdout[-2000:]}{proc.stderr[-2000:]}")
    return json.loads(proc.stdout.strip().splitlines()[-1])


def report(args, t_in: float, rtt: list[float], t_msg: float, t_graph: float,
           parts: list) -> None:
    t_rtt = statistics.mean(rtt)
    floor = t_in + args.cycles * t_msg
    ms = 1000.0
    print(f"in-process generation      {t_in * ms:8.1f} ms  (median of {args.generations})")
    print(f"bare round trip            {t_rtt * ms:8.3f} ms  (mean of {args.round_trips}; "
          f"median {statistics.median(rtt) * ms:.3f} ms)")
    print(f"messaging alone            {t_msg * args.cycles * ms:8.1f} ms  ({args.cycles} x "
          f"{t_msg * ms:.3f} ms: {t_msg / t_rtt:.2f} round trips per cycle for the four "
          f"lockstep messages, no work; mean of {args.round_trips} cycles)")
    print(f"graph generation           {t_graph * ms:8.1f} ms  (median of {args.generations}; "
          f"fitness identical to in-process)")
    print(f"floor = in-process + messaging alone = {floor * ms:.1f} ms; graph is "
          f"{t_graph / floor:.2f}x the floor, {(t_graph - floor) * ms:+.1f} ms "
          f"({(t_graph - floor) / args.cycles * ms:+.3f} ms per cycle)")
    print(f"target = 1.3 x floor = {1.3 * floor * ms:.1f} ms: "
          f"{'MET' if t_graph <= 1.3 * floor else 'MISSED'}")
    whole = args.run_generations * t_graph
    print(f"projected {args.run_generations}-generation run through the graph: {whole:.0f} s "
          f"(in-process {args.run_generations * t_in:.0f} s)")
    us = 1e6
    print("\nwhere a cycle of the graph goes (median us per cycle; hot loops in this process,")
    print("the nodes' calls at the same size; 'also alone': messaging alone does it too):")
    for name, seconds, alone in parts:
        note = "  also alone" if alone else ""
        print(f"  {name:<58}{seconds * us:8.1f}{note}")
    work = sum(seconds for _, seconds, alone in parts if alone is False)
    per_cycle = {"in-process cycle (its generation / cycles)": t_in / args.cycles,
                 "messaging alone, per cycle": t_msg,
                 "graph, per cycle": t_graph / args.cycles}
    for name, seconds in per_cycle.items():
        print(f"  {name:<58}{seconds * us:8.1f}")
    print(f"  {'the nodes work beyond messaging alone (the parts not also alone)':<58}"
          f"{work * us:8.1f}")
    left = t_graph / args.cycles - t_msg - work
    print(f"  {'left: graph - messaging alone - that work':<58}{left * us:8.1f}  (wake-ups, "
          "cold caches, kernel launches, scheduling of three processes on the CPUs)")


def report_tried(args, floor: float, tried: list) -> None:
    """The three-process graph with each --apart-env environment, against the same floor."""
    for env, seconds in tried:
        print(f"graph with {env:<42}{seconds * 1000:8.1f} ms  {seconds / floor:.2f}x the floor")


def report_composed(args, t_in: float, one: dict, env: str) -> None:
    """The composed graph (its process started with ``env``) against its own floor: the
    in-process generation plus the four lockstep messages passed between nodes of one
    process."""
    ms = 1000.0
    t_msg, t_graph = one["messaging"], one["graph"]
    floor = t_in + args.cycles * t_msg
    print(f"\ncomposed (world, controller and supervisor nodes in one process, one executor"
          f"{'; with ' + env if env else ''}):")
    print(f"messaging alone in one process {t_msg * args.cycles * ms:8.1f} ms  ({args.cycles} x "
          f"{t_msg * ms:.3f} ms; mean of {args.round_trips} cycles)")
    print(f"composed generation            {t_graph * ms:8.1f} ms  (median of "
          f"{args.generations}; fitness identical to in-process; in-process in that process, "
          f"OpenMP workers asleep between kernels: {one['in_process'] * ms:.1f} ms)")
    print(f"composed floor = in-process + messaging in one process = {floor * ms:.1f} ms; "
          f"composed is {t_graph / floor:.2f}x its floor")
    print(f"composed / in-process = {t_graph / t_in:.2f}x: target 1.5x "
          f"{'MET' if t_graph <= 1.5 * t_in else 'MISSED'}")


def environment(variables: str) -> dict:
    """{NAME: VALUE} of 'NAME=VALUE NAME=VALUE ...'."""
    return dict(item.split("=", 1) for item in variables.split())


def init_args(args) -> list[str]:
    """rclpy's arguments here: the supervisor's parameters (sizes, an unused out)."""
    return ["bench", "--ros-args", "-p", "out:=/tmp/econet-bench-unused",
            *[x for k, v in args.sizes.items() for x in ("-p", f"{k}:={v}")]]


def main() -> int:
    if "--echo" in sys.argv:
        return echo_main()
    if "--stand-in" in sys.argv:
        return stand_in_main(sys.argv[2], int(sys.argv[3]))
    if COMPOSED in sys.argv:
        return composed_main()
    args = parse_args()
    os.environ.setdefault("ROS_DOMAIN_ID", str(random.randint(120, 200)))
    import rclpy
    from econet_ros.nodes.runner import make_executor

    n_envs = args.population * args.trials
    print(f"generation: {args.population} econets x {args.trials} trials = {n_envs} "
          f"environments x {args.cycles} cycles; {os.cpu_count()} CPUs; executor "
          f"{os.environ.get('ECONET_EXECUTOR', 'events')}; load average "
          f"{os.getloadavg()[0]:.2f}", flush=True)
    t_in, expected, genomes = in_process(args)
    procs = []
    rclpy.init(args=init_args(args))
    try:
        executor = make_executor()
        procs.append(start([__file__, "--echo"], READY))
        node = rclpy.create_node("bench_ping")
        executor.add_node(node)
        parts = cycle_parts(args, executor, node)
        rtt = round_trip(executor, node, args.round_trips)
        stop(procs)
        procs[:] = [start([__file__, "--stand-in", role, str(n_envs)], READY)
                    for role in ("world", "controller")]
        t_msg = messaging_alone(executor, node, args.round_trips)
        stop(procs)
        sup = supervisor(executor)
        t_graph = apart(args, sup, genomes, expected, {})
        tried = [(env, apart(args, sup, genomes, expected, environment(env)))
                 for env in args.apart_env]
        if tried:       # the default once more: how far the machine drifted meanwhile
            tried.append(("(the default again)", apart(args, sup, genomes, expected, {})))
    finally:
        stop(procs)
        rclpy.try_shutdown()
    ones = [(env, composed(environment(env))) for env in ["", *args.composed_env]]
    report(args, t_in, rtt, t_msg, t_graph, parts)
    report_tried(args, t_in + args.cycles * t_msg, tried)
    for env, one in ones:
        report_composed(args, t_in, one, env)
    print(f"load average at the end: {os.getloadavg()[0]:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""Benchmark the node graph against its floor, in one run:

  1. in-process: the core's Evaluator.test_generation for one generation (no ROS);
  2. bare round trip: ping-pong of a tiny message between two processes (rclpy, same executor
     as the nodes), the cost of one lockstep cycle that does no work;
  3. messaging alone: the graph's four lockstep messages of a paper-size cycle (touch,
     proprioception, retina, muscle command: the same bytes) passed between a stand-in world and
     a stand-in controller that compute nothing, with this process listening to touch as the
     supervisor does; what the message design costs before any work is done;
  4. graph: the same generation through world_node and controller_node, each in its own
     process, driven by this process as the supervisor (SupervisorNode.test_generation);
and prints how far the graph is above its floor, floor = in-process + messaging alone (the
model's work plus the messages, neither of which the graph can avoid), against the target of
1.3 x the floor, and the projected time of a whole run.

Run after the set-up:  . scripts/env.sh && python scripts/bench_graph.py [--generations 5]
Defaults are paper size: 100 econets x 20 trials (2000 environments) x 100 cycles.
"""
from __future__ import annotations

import argparse
import os
import random
import signal
import statistics
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


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
    try:
        spin(node, executor)
    except KeyboardInterrupt:
        pass
    return 0


def paper_cycle_messages(n_envs: int) -> tuple[dict[str, bytes], bytes]:
    """One cycle's serialized sensor messages and muscle command, at their real sizes."""
    import numpy as np
    from econet_ros.config import Config
    from econet_ros.nodes import graph as common
    from econet_ros.world import N_MOTOR, World, sample_setups

    model = Config().model
    world = World(n_envs, model)
    world.reset(sample_setups(np.random.default_rng(0), n_envs, model))
    sensors = common.encode_sensors(world.observe(), 1, False)
    command = common.encode_command(1, 0, np.full((n_envs, N_MOTOR), 0.5))
    return sensors, command


def stand_in_main(role: str, n_envs: int) -> int:
    """A world or controller that only passes messages: the world answers every command with
    the same three sensor messages, the controller answers every complete set of three with the
    same command."""
    import rclpy
    from econet_ros.nodes import graph as common
    from econet_ros.nodes.runner import make_executor, spin
    from econet_ros.topics import COMMAND, SENSORS

    rclpy.init()
    node = rclpy.create_node(f"bench_{role}")
    sensors, command = paper_cycle_messages(n_envs)
    if role == "world":
        pubs = {part: common.publisher(node, part) for part in SENSORS}

        def on_command(_data: bytes) -> None:
            for part in SENSORS:
                pubs[part].publish(sensors[part])
        common.subscription(node, COMMAND, on_command, raw=True)
    else:
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
    kick = common.publisher(node, "muscle_command")
    spin_until(executor, lambda: kick.get_subscription_count() > 0
               and node.count_publishers("muscle_command") > 1
               and node.count_publishers("touch") > 0
               and node.count_subscribers("retina") > 0)
    kick.publish(paper_cycle_messages(1)[1])          # the first command; then they run alone
    spin_until(executor, lambda: len(touches) > n + 50)
    node.destroy_subscription(listen)
    node.destroy_publisher(kick)
    return (touches[n + 50] - touches[50]) / n


def start(args: list[str]) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, *args], cwd=REPO, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, start_new_session=True)


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


def spin_until(executor, done, timeout: float = 20.0) -> None:
    deadline = time.monotonic() + timeout
    while not done():
        if time.monotonic() > deadline:
            raise SystemExit("bench_graph: error: timed out waiting for the other process")
        executor.spin_once(timeout_sec=0.05)


def round_trip(executor, node, n: int) -> list[float]:
    from econet_msgs.msg import Touch
    from econet_ros.nodes import graph as common

    got = []
    pub = node.create_publisher(Touch, "ping", common.LOCKSTEP_QOS)
    node.create_subscription(Touch, "pong", got.append, common.LOCKSTEP_QOS)
    spin_until(executor, lambda: pub.get_subscription_count() > 0
               and node.count_publishers("pong") > 0)
    times = []
    for i in range(n + 50):              # the first 50 warm up
        t0 = time.perf_counter()
        pub.publish(Touch(cycle=i))
        spin_until(executor, lambda: len(got) > i)
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
    from econet_ros.evolution import Evaluator, initial_genomes

    evaluator = Evaluator(args.config)
    genomes = initial_genomes(args.config, evaluator.n_weights, 1, 1)
    evaluator.test_generation(genomes, 1, 1, 0)          # warm up (numba)
    times, fitness = [], []
    for g in range(args.generations):
        t0 = time.perf_counter()
        fitness.append(evaluator.test_generation(genomes, 1, 1, g).fitness)
        times.append(time.perf_counter() - t0)
    return statistics.median(times), fitness, genomes


def through_graph(args, executor, genomes, expected) -> float:
    """Median seconds of a generation through world_node and controller_node (this process
    as the supervisor), each checked against the in-process fitness."""
    import numpy as np
    from econet_ros.nodes.supervisor_node import SupervisorNode

    sup = SupervisorNode()
    sup.evaluator.executor = executor
    executor.add_node(sup)
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


def report(args, t_in: float, rtt: list[float], t_msg: float, t_graph: float) -> None:
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


def main() -> int:
    if "--echo" in sys.argv:
        return echo_main()
    if "--stand-in" in sys.argv:
        return stand_in_main(sys.argv[2], int(sys.argv[3]))
    args = parse_args()
    os.environ.setdefault("ROS_DOMAIN_ID", str(random.randint(120, 200)))
    import rclpy
    from econet_ros.nodes.runner import make_executor

    n_envs = args.population * args.trials
    print(f"generation: {args.population} econets x {args.trials} trials = {n_envs} "
          f"environments x {args.cycles} cycles; {os.cpu_count()} CPUs; executor "
          f"{os.environ.get('ECONET_EXECUTOR', 'events')}")
    t_in, expected, genomes = in_process(args)
    procs = []
    rclpy.init(args=["bench", "--ros-args", "-p", "out:=/tmp/econet-bench-unused",
                     *[x for k, v in args.sizes.items() for x in ("-p", f"{k}:={v}")]])
    try:
        executor = make_executor()
        procs.append(start([__file__, "--echo"]))
        node = rclpy.create_node("bench_ping")
        executor.add_node(node)
        rtt = round_trip(executor, node, args.round_trips)
        stop(procs)
        procs[:] = [start([__file__, "--stand-in", role, str(n_envs)])
                    for role in ("world", "controller")]
        t_msg = messaging_alone(executor, node, args.round_trips)
        stop(procs)
        procs[:] = [start(["-m", f"econet_ros.nodes.{role}_node"])
                    for role in ("world", "controller")]
        t_graph = through_graph(args, executor, genomes, expected)
    finally:
        stop(procs)
        rclpy.try_shutdown()
    report(args, t_in, rtt, t_msg, t_graph)
    return 0


if __name__ == "__main__":
    sys.exit(main())

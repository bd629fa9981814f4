#!/usr/bin/env python3
"""Benchmark of the in-process model core: econet-cycles per second and the time of a full
paper-size run (100 econets x 20 trials x 100 cycles x 200 generations = 4e7 econet-cycles).

    . scripts/env.sh && flock /tmp/econet-bench.lock python scripts/bench/bench_core.py [--generations N] [--condition normal] [--full]
    . scripts/env.sh && flock /tmp/econet-bench.lock python scripts/bench/bench_core.py --per-cycle   # the nodes' per-cycle API
    . scripts/env.sh && flock /tmp/econet-bench.lock python scripts/bench/bench_core.py --against REV [--pairs 4] [--study]

It times N paper-size generations after one warm-up generation (which compiles the kernels),
run as every command runs them (runs.evolve_into, result files included, into a temporary
folder), and prints the per-kernel split of one generation, so a regression shows where it came from.
--per-cycle instead times World.step/observe and FeedForwardNetwork.act/forward for 2000
environments (100 networks of random weights), as the world and controller nodes call them;
NUMBA_NUM_THREADS=1 gives their cost with one numba thread per node.
--against REV compares this checkout with the commit REV in one run: whole paper-size commands
alternated, each side's median, min and max, the ratio and the load average, and whether both
wrote the same results (scripts/bench/against.py). Run it before merging any change to a module
in econet_ros.KERNEL_MODULES or to runs.py, run_folders.py, evolution.py or trials.py.
"""
from __future__ import annotations

import argparse
import cProfile
import pstats
import sys
import tempfile
import time
import timeit
from pathlib import Path

import numba
import numpy as np

from econet_ros.config import CONDITIONS, Config
from econet_ros.controllers import _forward_batch
from econet_ros.plugins import make_controller
from econet_ros.evolution import InProcessEvaluator
from econet_ros.runs import evolve_into
from econet_ros.world import World, _sense_batch, sample_setups

from against import compare_against     # this folder's module (the script's folder is on the path)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--generations", type=int, default=20,
                        help="paper-size generations to time (default: %(default)s)")
    parser.add_argument("--condition", choices=CONDITIONS, default="normal")
    parser.add_argument("--full", action="store_true",
                        help="also time one complete 200-generation run")
    parser.add_argument("--per-cycle", action="store_true",
                        help="time the per-cycle API (2000 environments) instead")
    parser.add_argument("--against", metavar="REV",
                        help="instead, alternate whole paper-size `econet evolve --runs 1` "
                             "commands of this checkout and of commit REV")
    parser.add_argument("--pairs", type=int, default=4,
                        help="with --against: alternated pairs (default: %(default)s)")
    parser.add_argument("--study", action="store_true",
                        help="with --against: also alternate `econet study --runs 1`")
    args = parser.parse_args()
    if args.against:
        sys.exit(compare_against(args.against, args.pairs, args.study))
    if args.per_cycle:
        per_cycle(Config().replace(**{"evolution.condition": args.condition}))
        return

    config = Config().replace(**{"evolution.condition": args.condition,
                                 "evolution.generations": args.generations})
    e = config.evolution
    evaluator = InProcessEvaluator(config)
    evolve(config.replace(**{"evolution.generations": 1}), 99, evaluator)  # compile

    start = time.perf_counter()
    evolve(config, 1, evaluator)
    seconds = time.perf_counter() - start
    cycles = e.population * e.trials * e.cycles * args.generations
    per_generation = seconds / args.generations
    print(f"threads: {numba.get_num_threads()}  condition: {args.condition}")
    print(f"{args.generations} generations of {e.population} econets x {e.trials} trials x "
          f"{e.cycles} cycles: {seconds:.2f} s ({per_generation * 1e3:.1f} ms per generation)")
    print(f"econet-cycles per second: {cycles / seconds:,.0f}")
    print(f"projected full run (200 generations, 4e7 econet-cycles): "
          f"{per_generation * 200:.1f} s")

    if args.full:
        full = config.replace(**{"evolution.generations": 200})
        start = time.perf_counter()
        evolve(full, 1, evaluator)
        print(f"measured full run: {time.perf_counter() - start:.1f} s")

    profile = cProfile.Profile()
    profile.runcall(evaluator.test_generation, evaluator_genomes(evaluator), 1, 1, 0)
    print("\nwhere one generation's time goes:")
    pstats.Stats(profile).sort_stats("tottime").print_stats(6)


def evolve(config: Config, seed: int, evaluator: InProcessEvaluator) -> None:
    """One run through the loop every command uses, result files included, into a folder
    that is thrown away."""
    with tempfile.TemporaryDirectory(prefix="econet-bench-") as folder:
        evolve_into(Path(folder) / "run-01", config, seed, 1, evaluator)


def per_cycle(config: Config, n_envs: int = 2000, n_networks: int = 100) -> None:
    rng = np.random.default_rng(0)
    world = World(n_envs, config.model)
    world.reset(sample_setups(rng, n_envs, config.model))
    net = make_controller(config.evolution.condition, n_envs, config)
    net.load(rng.uniform(-10, 10, (n_networks, net.n_params)))
    obs = world.observe()
    inputs = obs.network_input()
    motor = net.act(obs)
    g = world.geometry
    senses, fixated = world.senses.copy(), world.fixated.copy()
    units = config.model.visual_units
    out = np.empty((n_envs, 5))
    calls = {
        "World.step": lambda: world.step(motor),
        "World.observe": world.observe,
        "FeedForwardNetwork.act": lambda: net.act(obs),
        "FeedForwardNetwork.forward": lambda: net.forward(inputs),
        "_sense_batch": lambda: _sense_batch(world.body, world.shoulder, world.elbow,
                                             world.object_xy, g, world.edges[0],
                                             world.edges[1], senses, fixated),
        "_forward_batch": lambda: _forward_batch(inputs[:, :units], inputs[:, units:-1],
                                                 inputs[:, -1], net.weights, net.block,
                                                 net.layers, net.buffer_size, out),
    }
    print(f"threads: {numba.get_num_threads()}  {n_envs} environments, {n_networks} networks")
    for name, call in calls.items():
        call()
        best = min(timeit.repeat(call, number=200, repeat=5)) / 200
        print(f"{name:28s} {best * 1e3:.3f} ms per call")


def evaluator_genomes(evaluator: InProcessEvaluator):
    from econet_ros.evolution import initial_genomes
    return initial_genomes(evaluator.config, evaluator.n_weights, 1, 1)


if __name__ == "__main__":
    main()

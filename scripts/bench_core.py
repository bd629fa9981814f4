#!/usr/bin/env python3
"""Benchmark of the in-process model core: econet-cycles per second and the time of a full
paper-size run (100 econets x 20 trials x 100 cycles x 200 generations = 4e7 econet-cycles).

    scripts/run-python scripts/bench_core.py [--generations N] [--condition normal]

It times N paper-size generations after one warm-up generation (which compiles the kernels)
and prints the per-kernel split of one generation, so a regression shows where it came from.
"""
from __future__ import annotations

import argparse
import cProfile
import pstats
import time

import numba

from econet_ros.config import CONDITIONS, Config
from econet_ros.evolution import Evaluator, evolve


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--generations", type=int, default=20,
                        help="paper-size generations to time (default: %(default)s)")
    parser.add_argument("--condition", choices=CONDITIONS, default="normal")
    parser.add_argument("--full", action="store_true",
                        help="also time one complete 200-generation run")
    args = parser.parse_args()

    config = Config().replace(**{"evolution.condition": args.condition,
                                 "evolution.generations": args.generations})
    e = config.evolution
    evaluator = Evaluator(config)
    evolve(config.replace(**{"evolution.generations": 1}), 99, 1, evaluator)  # compile

    start = time.perf_counter()
    evolve(config, 1, 1, evaluator)
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
        evolve(full, 1, 1, evaluator)
        print(f"measured full run: {time.perf_counter() - start:.1f} s")

    profile = cProfile.Profile()
    profile.runcall(evaluator.test_generation, evaluator_genomes(evaluator), 1, 1, 0)
    print("\nwhere one generation's time goes:")
    pstats.Stats(profile).sort_stats("tottime").print_stats(6)


def evaluator_genomes(evaluator: Evaluator):
    from econet_ros.evolution import initial_genomes
    return initial_genomes(evaluator.config, evaluator.n_weights, 1, 1)


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Benchmark of the Gymnasium vector environment and the other optimizers, in one run:

  1. the in-process engine (InProcessEvaluator.test_generation: whole trials in one compiled
     loop, the network included) in econet-cycles per second, paper-size generations of 2000 envs;
  2. the Gymnasium vector environment with 2000 environments stepped by a fixed action array
     (no Python-side policy), and the paper's network's own compiled forward on the same
     observations timed separately; target: the vector env at least 0.5x the engine's rate;
  3. a whole run of the same budget under the GA, CMA-ES and the ES (same settings, same seed,
     through runs.evolve_into); target: CMA-ES at most 1.5x the GA's time.

    . scripts/env.sh && flock /tmp/econet-bench.lock python scripts/bench/bench_gym.py
    ... python scripts/bench/bench_gym.py --repeats 5 --generations 50   # quicker
"""
from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import econet_ros  # noqa: F401  before numpy: one BLAS thread (econet_ros/__init__.py)
import numba
import numpy as np

from econet_ros.config import Config
from econet_ros.controllers import FourLayerNetwork
from econet_ros.evolution import InProcessEvaluator, genome_weights, initial_genomes
from econet_ros.gym import ReachVectorEnv
from econet_ros.runs import evolve_into


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5,
                        help="timings of each rate, taken in turns so that a change of load "
                             "hits all of them; each prints its range (default: 5)")
    parser.add_argument("--generations", type=int, default=200,
                        help="generations of each optimizer's run (default: 200, the paper's)")
    args = parser.parse_args()
    config = Config()
    e = config.evolution
    print(f"threads: {numba.get_num_threads()}; {e.population} econets x {e.trials} trials "
          f"x {e.cycles} cycles per generation")
    rates = Rates(config)
    engine, vector, forward = zip(*(rates.measure() for _ in range(args.repeats)))
    with_policy = [1 / (1 / v + 1 / f) for v, f in zip(vector, forward)]
    report("in-process engine", engine)
    report("vector env, fixed actions", vector)
    report("network forward alone", forward)
    report("vector env + network forward", with_policy)
    ratios = [v / g for v, g in zip(vector, engine)]
    with_ratios = [p / g for p, g in zip(with_policy, engine)]
    print(f"vector env / engine, per turn: {spread(ratios)} (target >= 0.5); with the "
          f"network's forward {spread(with_ratios)}")
    runs = {name: run_seconds(config.replace(**{"evolution.optimizer": name,
                                                "evolution.generations": args.generations}))
            for name in ("ga", "cmaes", "es")}
    ga_total, ga_tests = runs["ga"]
    for name, (total, tests) in runs.items():
        same_tests = (ga_tests + total - tests) / ga_total
        print(f"{name:5s} run of {args.generations} generations: {total:5.1f} s = tests "
              f"{tests:5.1f} s + breeding and writing {total - tests:4.1f} s; "
              f"{total / ga_total:.2f}x the GA, {same_tests:.2f}x with the GA's tests")
    print("target: cmaes <= 1.5x the GA (tests cost what the evolved econets look at, and a "
          "busy machine slows whole runs unevenly: the second ratio compares breeding alone)")


class Rates:
    """econet-cycles/s of three ways to run 2000 environments for 5 trials: whole paper-size
    generations in process (the network included); the vector env stepped with a fixed action
    array (with its autoreset steps); the four-layer network's forward on its observations."""

    def __init__(self, config: Config):
        self.config = config
        e = config.evolution
        self.n = e.population * e.trials
        self.steps = 5 * (e.cycles + 1)
        self.evaluator = InProcessEvaluator(config)
        self.genomes = initial_genomes(config, self.evaluator.n_weights, 1, 1)
        self.envs = ReachVectorEnv(self.n, config)
        self.obs, _ = self.envs.reset(seed=1)
        self.actions = np.random.default_rng(1).random((self.n, 5))
        self.net = FourLayerNetwork(self.n, config)
        self.net.load(genome_weights(config, self.genomes))
        self.turn = 0
        self.measure()                                              # compile

    def measure(self) -> tuple[float, float, float]:
        e = self.config.evolution
        start = time.perf_counter()
        for offset in range(5):
            self.evaluator.test_generation(self.genomes, 1, 1, 5 * self.turn + offset)
        engine = 5 * self.n * e.cycles / (time.perf_counter() - start)
        self.turn += 1
        return engine, self.per_step(self.envs.step, self.actions), \
            self.per_step(self.net.forward, self.obs)

    def per_step(self, call, argument) -> float:
        start = time.perf_counter()
        for _ in range(self.steps):
            call(argument)
        return self.n * self.steps / (time.perf_counter() - start)


def run_seconds(config: Config) -> tuple[float, float]:
    """Wall time of one whole run into a scratch folder, and the part spent testing
    generations (the rest: breeding and writing)."""
    evaluator = InProcessEvaluator(config)
    test_generation, tests = evaluator.test_generation, [0.0]

    def timed(*args, **kwargs):
        start = time.perf_counter()
        result = test_generation(*args, **kwargs)
        tests[0] += time.perf_counter() - start
        return result

    evaluator.test_generation = timed
    with tempfile.TemporaryDirectory() as scratch:
        start = time.perf_counter()
        evolve_into(Path(scratch) / "run-01", config, 1, 1, evaluator)
        return time.perf_counter() - start, tests[0]


def spread(values, scale: float = 1.0) -> str:
    """min-max (median): a busy machine slows some turns a lot, the median little."""
    values = np.asarray(values) / scale
    return f"{values.min():.2f}-{values.max():.2f} (median {np.median(values):.2f})"


def report(label: str, rates: list[float]) -> None:
    print(f"{label:30s} {spread(rates, 1e6)} million econet-cycles/s")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Benchmark of what a study adds to a bare run: the time of N paper-size generations evolved
as ``econet study`` evolves them (science.study.evolve_with_behaviour: behaviour.csv included)
over the time of the same generations evolved as ``econet evolve`` does (runs.evolve_into), same
seed and settings, warm kernels, alternated within one process so that a busy machine slows
both alike. The default is whole paper-size runs (200 generations, about 15 s a pair), the
figure the target is about; the first few generations of a run are not a sample of it.

    . scripts/env.sh && flock /tmp/econet-bench.lock python scripts/bench/bench_study.py [--generations N] [--repeats R]
"""
from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

import numba

from econet_ros.config import CONDITIONS, Config
from econet_ros.evolution import InProcessEvaluator
from econet_ros.runs import evolve_into
from econet_ros.science.study import evolve_with_behaviour


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--generations", type=int, default=200,
                        help="paper-size generations per timing (default: %(default)s)")
    parser.add_argument("--repeats", type=int, default=3, help="timings each way")
    parser.add_argument("--condition", choices=CONDITIONS, default="normal")
    args = parser.parse_args()
    config = Config().replace(**{"evolution.condition": args.condition,
                                 "evolution.generations": args.generations})
    evaluator = InProcessEvaluator(config)
    ways = {"bare": lambda folder: evolve_into(folder, config, 1, 1, evaluator),
            "study": lambda folder: evolve_with_behaviour([(folder, 1)], config, 1, evaluator)}
    for way in ways.values():      # compile
        timed(way)
    seconds = {name: [] for name in ways}
    for _ in range(args.repeats):
        for name, way in ways.items():
            seconds[name].append(timed(way))
    print(f"threads: {numba.get_num_threads()}  condition: {args.condition}  "
          f"{args.generations} paper-size generations per timing")
    for name, times in seconds.items():
        print(f"{name:6s} " + "  ".join(f"{t:.2f} s" for t in times))
    ratios = [s / b for s, b in zip(seconds["study"], seconds["bare"])]
    print("study / bare: " + "  ".join(f"{r:.2f}" for r in ratios))
    print(f"study / bare: median {statistics.median(ratios):.2f}, range {min(ratios):.2f}-"
          f"{max(ratios):.2f} over {len(ratios)} pairs; best times "
          f"{min(seconds['study']) / min(seconds['bare']):.2f}")


def timed(way) -> float:
    with tempfile.TemporaryDirectory(prefix="econet-bench-") as folder:
        start = time.perf_counter()
        way(Path(folder) / "run-01")
        return time.perf_counter() - start


if __name__ == "__main__":
    main()

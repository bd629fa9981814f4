#!/usr/bin/env python3
"""Benchmark of the GPU engine (econet_ros.cuda): many paper-size runs evolved side by side, each
generation one kernel launch for all of them, and the identity check against the CPU.

    . scripts/env.sh && python scripts/bench/bench_cuda.py              # on a machine with a GPU
    python scripts/bench/bench_cuda.py --simulate                       # tiny, numba's simulator

For 1, 10, 100 and 340 runs (--runs) it evolves every run for --generations generations: each
generation the trial starts, genome decoding and movement noise are drawn on the host as on the
CPU, one launch tests every run's population (transfers included), and the GA breeds each run on
the host. It prints the launch's ms per generation and econet-cycles per second (an econet-cycle
is one trial's cycle), the host's ms per generation, the time of 200 generations at that pace,
and the identity check: every run's last generation tested again on the CPU
(InProcessEvaluator), with per-trial fitness, latency, separations and the final body, shoulder
and elbow angles compared bit for bit. On a fresh machine the first launch compiles the kernel
(printed apart) and the CPU check compiles the CPU kernels: all within 5 minutes on one GPU.
"""
from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

PAPER_RUNS = (1, 10, 100, 340)
TINY = {"evolution.population": 4, "evolution.parents": 2, "evolution.trials": 3,
        "evolution.cycles": 10}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", default=",".join(map(str, PAPER_RUNS)),
                        help="comma-separated numbers of runs tested together "
                             "(default: %(default)s)")
    parser.add_argument("--generations", type=int, default=3,
                        help="timed generations per number of runs (default: %(default)s)")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--simulate", action="store_true",
                        help="tiny runs (1 and 2) under numba's CUDA simulator: no GPU needed")
    args = parser.parse_args(argv)
    if args.simulate:
        os.environ["NUMBA_ENABLE_CUDASIM"] = "1"     # before numba.cuda is imported
    sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
    from econet_ros.config import Config
    from econet_ros.cuda import CudaEngine
    from econet_ros.evolution import InProcessEvaluator

    config = Config().replace(**TINY) if args.simulate else Config()
    sizes = (1, 2) if args.simulate else tuple(int(r) for r in args.runs.split(","))
    engine, cpu = CudaEngine(config), InProcessEvaluator(config)
    e = config.evolution
    print(f"{'simulated GPU' if args.simulate else device_name(engine)}; runs of {e.population} "
          f"econets x {e.trials} trials x {e.cycles} cycles, {args.generations} timed "
          "generations each")
    started = time.perf_counter()
    evolve(engine, config, args.seed, 1, 1)
    print(f"first launch (compiles the kernel): {time.perf_counter() - started:.1f} s")
    print(f"{'runs':>5} {'launch ms/gen':>14} {'econet-cycles/s':>16} {'host ms/gen':>12} "
          f"{'200 gens s':>11}  identical to the CPU")
    all_equal = True
    for runs in sizes:
        launch, host, last = evolve(engine, config, args.seed, runs, args.generations)
        cycles = runs * e.population * e.trials * e.cycles
        equal, differing = identity(cpu, last, args.seed)
        all_equal &= equal == runs
        print(f"{runs:>5} {launch * 1e3:>14.1f} {cycles / launch:>16,.0f} {host * 1e3:>12.1f} "
              f"{(launch + host) * 200:>11.1f}  {equal}/{runs} runs"
              + (f" ({differing})" if differing else ""))
    return 0 if all_equal else 1


def device_name(engine) -> str:
    device = engine.kernels.cuda.get_current_device()
    name = device.name.decode() if isinstance(device.name, bytes) else device.name
    return f"GPU: {name}"


def evolve(engine, config, seed: int, runs: int, generations: int):
    """``generations`` generations of runs 1..runs, tested in one launch each; returns the mean
    launch and host seconds per generation and the last generation tested (per run: genomes,
    generation, the launch's measures and final state)."""
    from econet_ros.evolution import (generation_setups, genome_weights, initial_genomes,
                                      next_generation, noise_seed, score_generation)
    numbers = range(1, runs + 1)
    genomes = [initial_genomes(config, engine.controller.n_params, seed, run)
               for run in numbers]
    launch = host = 0.0
    for generation in range(generations):
        started = time.perf_counter()
        weights = [genome_weights(config, g) for g in genomes]
        setups = [generation_setups(config, seed, run, generation) for run in numbers]
        noise = [noise_seed(seed, run, generation) for run in numbers]
        prepared = time.perf_counter()
        batch = engine.test_populations(weights, setups, noise)
        tested = time.perf_counter()
        last = (list(genomes), generation, batch)
        genomes = [next_generation(config, score_generation(config, generation, g, m), seed,
                                   run) for g, m, run in zip(genomes, batch.measures, numbers)]
        launch += tested - prepared
        host += (prepared - started) + (time.perf_counter() - tested)
    return launch / generations, host / generations, last


def identity(cpu, last, seed: int) -> tuple[int, str]:
    """How many runs' last generation the CPU tests to the same bits, and what differed (trials
    per quantity)."""
    genomes, generation, batch = last
    equal, differing = 0, {}
    for k, run_genomes in enumerate(genomes):
        measures = cpu.test_generation(run_genomes, seed, k + 1, generation).measures
        same = True
        for name in ("fitness", "success", "latency", "separations", "body", "shoulder",
                     "elbow"):
            on_cpu, on_gpu = (np.ravel(getattr(cpu.world, name)), getattr(batch, name)[k]) \
                if hasattr(batch, name) else (getattr(measures, name).ravel(),
                                              getattr(batch.measures[k], name))
            if on_cpu.tobytes() != np.asarray(on_gpu, dtype=on_cpu.dtype).tobytes():
                same = False
                differing[name] = differing.get(name, 0) + int(np.sum(on_cpu != on_gpu))
        equal += same
    return equal, ", ".join(f"{name}: {n} trials differ" for name, n in differing.items())


if __name__ == "__main__":
    sys.exit(main())

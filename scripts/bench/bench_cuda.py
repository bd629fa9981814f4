#!/usr/bin/env python3
"""Benchmark of the GPU engine (econet_ros.cuda): many paper-size runs evolved side by side, each
generation one kernel launch for all of them, and the identity check against the CPU.

    . scripts/env.sh && python scripts/bench/bench_cuda.py              # on a machine with a GPU
    python scripts/bench/bench_cuda.py --simulate                       # tiny, numba's simulator

For 1, 10, 100 and 340 runs (--runs) it evolves every run for --generations generations: each
generation CudaEvaluator.test_generations tests every run's population in one launch (trial
starts, genome decoding and movement noise drawn on the host as on the CPU, transfers and
scoring included), then the GA breeds each run on the host. It prints the test's ms per
generation and econet-cycles per second (an econet-cycle is one trial's cycle), the GA's ms per
generation, the time of 200 generations at that pace (without writing result files), and the
identity check: every run's last generation tested again on the CPU
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
    from econet_ros.cuda import CudaEvaluator
    from econet_ros.evolution import InProcessEvaluator

    config = Config().replace(**TINY) if args.simulate else Config()
    sizes = (1, 2) if args.simulate else tuple(int(r) for r in args.runs.split(","))
    gpu, cpu = CudaEvaluator(config), InProcessEvaluator(config)
    e = config.evolution
    print(f"{'simulated GPU' if args.simulate else device_name(gpu.engine)}; runs of {e.population} "
          f"econets x {e.trials} trials x {e.cycles} cycles, {args.generations} timed "
          "generations each")
    started = time.perf_counter()
    evolve(gpu, config, args.seed, 1, 1)
    print(f"first launch (compiles the kernel): {time.perf_counter() - started:.1f} s")
    print(f"{'runs':>5} {'test ms/gen':>12} {'econet-cycles/s':>16} {'GA ms/gen':>10} "
          f"{'200 gens s':>11}  identical to the CPU")
    all_equal = True
    for runs in sizes:
        test, breed, last = evolve(gpu, config, args.seed, runs, args.generations)
        cycles = runs * e.population * e.trials * e.cycles
        equal, differing = identity(cpu, last)
        all_equal &= equal == runs
        print(f"{runs:>5} {test * 1e3:>12.1f} {cycles / test:>16,.0f} {breed * 1e3:>10.1f} "
              f"{(test + breed) * 200:>11.1f}  {equal}/{runs} runs"
              + (f" ({differing})" if differing else ""))
    return 0 if all_equal else 1


def device_name(engine) -> str:
    device = engine.kernels.cuda.get_current_device()
    name = device.name.decode() if isinstance(device.name, bytes) else device.name
    return f"GPU: {name}"


def evolve(evaluator, config, seed: int, runs: int, generations: int):
    """``generations`` generations of runs 1..runs, tested in one launch each
    (CudaEvaluator.test_generations: starts, decoding and noise drawn on the host, the launch,
    the scoring) and bred on the host by the GA; returns the mean seconds per generation of the
    test and of the breeding, and the last test (its requests and its launch's findings)."""
    from econet_ros.evolution import initial_genomes, next_generation
    numbers = range(1, runs + 1)
    genomes = [initial_genomes(config, evaluator.n_weights, seed, run) for run in numbers]
    test = breed = 0.0
    for generation in range(generations):
        started = time.perf_counter()
        requests = [(g, seed, run, generation) for g, run in zip(genomes, numbers)]
        results = evaluator.test_generations(requests)
        tested = time.perf_counter()
        genomes = [next_generation(config, result, seed, run)
                   for result, run in zip(results, numbers)]
        test += tested - started
        breed += time.perf_counter() - tested
    return test / generations, breed / generations, (requests, evaluator.last)


def identity(cpu, last) -> tuple[int, str]:
    """How many runs' last generation the CPU tests to the same bits, and what differed (trials
    per quantity)."""
    requests, batch = last
    equal, differing = 0, {}
    for k, request in enumerate(requests):
        measures = cpu.test_generation(*request).measures
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

#!/usr/bin/env python3
"""Benchmark: a sweep on local Ray against the same runs done one after another in one process.

    . scripts/env.sh && flock /tmp/econet-bench.lock python scripts/bench/bench_sweep.py [--help]

It builds a sweep of CELLS x SEEDS paper-size runs of the normal condition (cells differ in
the mutation reading, so every run is distinct), times them as `econet evolve` runs them (one
process, the kernels' own threads over the cores, `runs.evolve_into` run after run) and as
`econet sweep run` runs them (a local Ray instance started and stopped inside the timing, one
single-threaded worker per core), checks that both wrote identical run folders, and prints the
two wall times and their ratio (target: sweep <= 1.1 x sequential).
"""
from __future__ import annotations

import argparse
import shutil
import sys
import tempfile
import time
from pathlib import Path

CELLS = ("per-bit", "exact", "weights")


def spec_text(generations: int, seeds: int) -> str:
    cells = "\n".join(f'[cells.{mode}]\nset = {{"evolution.mutation_mode" = "{mode}"}}\n'
                      for mode in CELLS)
    return (f'name = "bench"\ngenerations = {generations}\nseeds = {{first = 1, count = '
            f'{seeds}}}\nconditions = ["normal"]\nbehaviour = false\n\n{cells}')


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--generations", type=int, default=200,
                        help="generations per run (default: the paper's 200)")
    parser.add_argument("--seeds", type=int, default=2,
                        help=f"seeds per cell; runs = {len(CELLS)} x seeds (default 2)")
    args = parser.parse_args()
    if args.generations < 1 or args.seeds < 1:
        parser.error("--generations and --seeds must be at least 1")

    from econet_ros.runs import evolve_into
    from econet_ros.science.sweeps.spec import load_spec
    from econet_ros.science.sweeps.runner import run_sweep

    work = Path(tempfile.mkdtemp(prefix="econet-bench-sweep-"))
    try:
        path = work / "bench.toml"
        path.write_text(spec_text(args.generations, args.seeds))
        spec = load_spec(path)
        runs = spec.runs()
        evolve_into(work / "warm", runs[0].config.replace(**{"evolution.generations": 1}),
                    1, 1)                                  # kernels loaded before timing
        started = time.perf_counter()
        for run in runs:
            evolve_into(run.folder(work / "sequential"), run.config, run.seed, 1)
        sequential = time.perf_counter() - started
        started = time.perf_counter()
        run_sweep(spec, work / "sweep", progress=False)
        swept = time.perf_counter() - started
        same = all((run.folder(work / "sweep") / name).read_bytes() ==
                   (run.folder(work / "sequential") / name).read_bytes()
                   for run in runs for name in ("metrics.csv", "genomes.npy", "fitness.npy"))
    finally:
        shutil.rmtree(work, ignore_errors=True)
    print(f"{len(runs)} runs x {args.generations} generations (population 100, 20 trials x 100 "
          f"cycles), normal condition")
    print(f"one after another, one process  {sequential:7.1f} s")
    print(f"econet sweep, local Ray         {swept:7.1f} s  (Ray start and stop included)")
    print(f"ratio sweep / sequential        {swept / sequential:7.2f}  (target <= 1.10: "
          f"{'met' if swept <= 1.1 * sequential else 'MISSED'}); results identical: {same}")
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())

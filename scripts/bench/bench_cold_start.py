#!/usr/bin/env python3
"""Benchmark of the first command after set-up: does a user still pay for compiling kernels?

    . scripts/env.sh && flock /tmp/econet-bench.lock python scripts/bench/bench_cold_start.py

In an empty kernel cache of its own (NUMBA_CACHE_DIR, so the user's cache is untouched) it times,
in fresh processes: `econet evolve` with no compiled kernels (what a fresh clone paid before
scripts/setup compiled them), python -m econet_ros.kernels (the set-up step), then the first
`econet evolve` after it and a second, warm one. All runs are one paper-size run (200
generations) with the same seed; target: first after set-up <= 1.5x the warm run.
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def timed(args: list[str], env: dict) -> float:
    start = time.perf_counter()
    subprocess.run([sys.executable, *args], check=True, env=env, cwd=ROOT,
                   stdout=subprocess.DEVNULL)
    return time.perf_counter() - start


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--generations", type=int, default=200,
                        help="generations of each evolve run (default: %(default)s)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="econet-cold-") as folder:
        env = dict(os.environ, NUMBA_CACHE_DIR=str(Path(folder) / "cache"))

        def evolve(name: str) -> float:
            return timed(["-m", "econet_ros", "evolve", "--out", str(Path(folder) / name),
                          "--runs", "1", "--quiet", "--generations", str(args.generations)],
                         env)

        figures = {"econet evolve, nothing compiled": evolve("uncompiled")}
        subprocess.run(["rm", "-rf", env["NUMBA_CACHE_DIR"]], check=True)
        figures["python -m econet_ros.kernels (set-up)"] = timed(
            ["-m", "econet_ros.kernels"], env)
        figures["first econet evolve after set-up"] = evolve("first")
        figures["warm econet evolve"] = evolve("warm")
    for name, seconds in figures.items():
        print(f"{name:40s} {seconds:6.1f} s")
    warm = figures["warm econet evolve"]
    print(f"first after set-up / warm: {figures['first econet evolve after set-up'] / warm:.2f}x "
          f"(target <= 1.5x); nothing compiled / warm: "
          f"{figures['econet evolve, nothing compiled'] / warm:.2f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())

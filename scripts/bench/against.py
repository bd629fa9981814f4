"""bench_core.py --against REV: this checkout's core against the commit REV, in one run.

REV is checked out into a temporary git worktree (same .venv; its kernels compile into a cache
folder keyed by its own kernel sources, so neither side runs the other's). Each side is first
warmed by a short run (which compiles what its cache lacks), then whole commands alternate,
this side first in odd pairs and REV first in even ones, so that a busy machine slows both
alike: a paper-size `econet evolve --runs 1`, and with --study an `econet study --runs 1`.
Each side writes into a folder of its own, and the two sides' result files are compared.
"""
from __future__ import annotations

import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
EVOLVE = ("evolve", "--runs", "1", "--quiet")
STUDY = ("study", "--runs", "1", "--quiet")
WARM = ("--generations", "2")
# The files a run or a study writes that hold results (not paths, times or code versions).
COMPARED = {"evolve": ("run-01/run.json", "run-01/metrics.csv", "run-01/genomes.npy",
                       "run-01/fitness.npy", "run-01/best_genomes.npy"),
            "study": ("claims.csv", "data/per_generation.csv.gz")}


def compare_against(rev: str, pairs: int, study: bool) -> int:
    """Time both sides and print the figures; 0 when the results are identical, else 1."""
    commit = resolve(rev)
    commands = {"evolve": EVOLVE} | ({"study": STUDY} if study else {})
    with tempfile.TemporaryDirectory(prefix="econet-against-") as folder:
        tree = Path(folder) / "tree"
        git("worktree", "add", "--detach", "--quiet", str(tree), commit)
        try:
            sides = {"this": REPO, rev: tree}
            print(f"this checkout ({describe(REPO)}) against {rev} ({describe(tree)}); "
                  f"load average {os.getloadavg()[0]:.2f}", flush=True)
            for name, root in sides.items():
                for kind, command in commands.items():
                    run_side(root, command + WARM, Path(folder) / "warm" / name / kind)
            seconds = {kind: {name: [] for name in sides} for kind in commands}
            for pair in range(pairs):
                order = list(sides.items())[::1 if pair % 2 == 0 else -1]
                for kind, command in commands.items():
                    for name, root in order:
                        out = Path(folder) / "out" / name / kind / str(pair)
                        seconds[kind][name].append(run_side(root, command, out))
                print(f"pair {pair + 1}/{pairs} done, load average {os.getloadavg()[0]:.2f}",
                      flush=True)
            for kind in commands:
                report(kind, seconds[kind], rev)
            return 0 if all(identical(Path(folder) / "out", kind, rev) for kind in commands) else 1
        finally:
            git("worktree", "remove", "--force", str(tree))


def run_side(root: Path, command: tuple[str, ...], out: Path) -> float:
    """Seconds that `python -m econet_ros COMMAND --out OUT` takes with ``root``'s sources."""
    theirs = [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep)
              if p and Path(p).resolve() != REPO]
    env = os.environ | {"PYTHONPATH": os.pathsep.join([str(root), *theirs])}
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "econet_ros", *command, "--out", str(out)],
                          cwd=root, env=env, capture_output=True, text=True)
    seconds = time.perf_counter() - start
    if done.returncode != 0:
        last = (done.stderr.strip() or done.stdout.strip()).splitlines()[-1:]
        sys.exit(f"bench_core: `econet {' '.join(command)}` failed in {root}: {last}")
    return seconds


def report(kind: str, seconds: dict[str, list[float]], rev: str) -> None:
    """Each side's median, min and max, and the ratio of the medians (this / REV)."""
    print(f"\n{kind} ({' '.join(EVOLVE if kind == 'evolve' else STUDY)}), "
          f"{len(seconds['this'])} pairs:")
    for name, values in seconds.items():
        print(f"  {name:>12s}: median {statistics.median(values):6.2f} s, min {min(values):6.2f},"
              f" max {max(values):6.2f}  ({', '.join(f'{v:.2f}' for v in values)})")
    ratios = [a / b for a, b in zip(seconds["this"], seconds[rev])]
    print(f"  this / {rev}: {statistics.median(seconds['this']) / statistics.median(seconds[rev]):.3f}"
          f" (ratio of the medians; per pair {min(ratios):.3f}-{max(ratios):.3f})")


def identical(out: Path, kind: str, rev: str) -> bool:
    """Whether both sides wrote the same result files in every pair (and say which differ)."""
    differing = sorted({name for pair in (out / "this" / kind).iterdir()
                        for name in COMPARED[kind]
                        if (pair / name).read_bytes() !=
                        (out / rev / kind / pair.name / name).read_bytes()})
    print(f"  results: {'identical' if not differing else 'DIFFERENT: ' + ', '.join(differing)}")
    return not differing


def resolve(rev: str) -> str:
    """The commit REV names, or exit with one line."""
    found = subprocess.run(["git", "rev-parse", "--verify", "--quiet", f"{rev}^{{commit}}"],
                           cwd=REPO, capture_output=True, text=True)
    if found.returncode != 0:
        sys.exit(f"bench_core: --against {rev}: no such commit in {REPO}")
    return found.stdout.strip()


def describe(root: Path) -> str:
    """The commit a tree holds, and whether it has changes."""
    head = subprocess.run(["git", "rev-parse", "--short=12", "HEAD"], cwd=root,
                          capture_output=True, text=True).stdout.strip()
    dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=root,
                           capture_output=True, text=True).stdout.strip()
    return head + (" with uncommitted changes" if dirty else "")


def git(*args: str) -> None:
    subprocess.run(["git", *args], cwd=REPO, check=True)

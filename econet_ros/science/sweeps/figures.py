"""Figures of a sweep: each outcome per cell and condition with its 95% interval over seeds,
and the paired comparisons as a forest plot."""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..figures import hand_path_gallery, save  # noqa: E402
from ..stats import Estimate  # noqa: E402
from .plan import SweepSpec  # noqa: E402

COLORS = {"normal": "tab:blue", "three-layer": "tab:orange", "random": "tab:gray"}
SHOWN = ("top_fitness", "top_successes", "top_separations_per_success", "top_latency_success",
         "top_eye_speed_fix", "top_approach_fix")


def outcome_figure(spec: SweepSpec, late: dict[tuple[str, str, str], Estimate],
                   labels: dict[str, str], folder: Path) -> Path:
    """Late-window mean and 95% CI of the main outcomes, one panel each, cells along x;
    ``late`` holds the estimates by (cell, condition, outcome)."""
    folder.mkdir(parents=True, exist_ok=True)
    fig, axes = plt.subplots(2, 3, figsize=(13, 7.5), squeeze=False)
    names = [c.name for c in spec.cells]
    for ax, name in zip(axes.flat, SHOWN):
        for k, condition in enumerate(("normal", "three-layer", "random")):
            xs, means, errors = [], [], [[], []]
            for i, cell in enumerate(spec.cells):
                if condition not in cell.conditions:
                    continue
                est = late.get((cell.name, condition, name))
                if est is None or not est.n:
                    continue
                lo, hi = (est.lo, est.hi) if np.isfinite(est.lo) else (est.mean, est.mean)
                xs.append(i + (k - 1) * 0.2)
                means.append(est.mean)
                errors[0].append(est.mean - lo)
                errors[1].append(hi - est.mean)
            if xs:
                ax.errorbar(xs, means, yerr=errors, fmt="o", color=COLORS[condition],
                            label=condition, capsize=3, ms=4)
        ax.set_xticks(range(len(names)))
        ax.set_xticklabels(names, rotation=30, ha="right", fontsize=7)
        ax.set_title(labels[name], fontsize=9)
    axes.flat[0].legend(fontsize=7)
    fig.suptitle(f"Sweep '{spec.name}': late-window outcomes, mean and 95% t interval over "
                 f"{len(spec.seeds)} seeds")
    return save(fig, folder / "outcomes.png", dpi=90)


def comparison_figure(compared: list[dict], folder: Path) -> Path:
    """Every late-window comparison of the main outcomes: mean difference and 95% CI."""
    folder.mkdir(parents=True, exist_ok=True)
    late = [r for r in compared if r["window"] == "late" and r["outcome"] in SHOWN]
    fig, axes = plt.subplots(1, len(SHOWN), figsize=(3.2 * len(SHOWN), 1 + 0.35 * max(
        1, len(late) // len(SHOWN))), squeeze=False, sharey=True)
    for ax, name in zip(axes.flat, SHOWN):
        mine = [r for r in late if r["outcome"] == name]
        ys = np.arange(len(mine))
        mean = np.array([r["mean_difference"] for r in mine])
        lo = np.array([r["ci_low"] for r in mine])
        hi = np.array([r["ci_high"] for r in mine])
        ok = np.isfinite(lo)
        ax.errorbar(mean[ok], ys[ok], xerr=[mean[ok] - lo[ok], hi[ok] - mean[ok]], fmt="o",
                    capsize=2, ms=3)
        ax.plot(mean[~ok], ys[~ok], "o", mfc="none")
        ax.axvline(0, color="k", lw=0.6)
        ax.set_title(name, fontsize=8)
        ax.set_yticks(ys)
        ax.set_yticklabels([f"{r['a']} - {r['b']}" for r in mine], fontsize=6)
    fig.suptitle("Paired comparisons (a - b), late window, 95% t interval over seeds",
                 fontsize=9)
    return save(fig, folder / "comparisons.png", dpi=90)


def gallery(runs: list[tuple[str, Path]], folder: Path) -> Path:
    """The study's hand-path gallery for the first seed of every cell and condition."""
    fig = hand_path_gallery(runs, trials=4)
    return save(fig, folder / "gallery.png", dpi=70)

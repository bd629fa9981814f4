"""The studies' own figures: the map of mutational load (H3) and E1's holding per cell."""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..science.figures import save  # noqa: E402
from ..science.stats import share  # noqa: E402


LOAD_MAP = "load_map.png"


def load_map_figure(cells: list[dict], folder: Path) -> Path:
    """The map of H3: per cell the share of runs that hold (with its exact interval) and the
    late top-20 fitness (mean over seeds) against the bit flips per copy, one line per network
    size (four-layer solid, three-layer dashed); the paper's 2% is ringed."""
    folder.mkdir(parents=True, exist_ok=True)
    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 4.8))
    sizes = list(dict.fromkeys((c["three_layer"], c["size"], c["weights"]) for c in cells))
    shades = [plt.cm.tab10(i) for i in range(len(sizes))]
    for (three, size, weights), color in zip(sizes, shades):
        mine = sorted((c for c in cells if c["size"] == size), key=lambda c: c["load"])
        load = [c["load"] for c in mine]
        held = np.array([[c["holding"].mean, c["holding"].lo, c["holding"].hi] for c in mine])
        style = "--" if three else "-"
        label = f"{'three' if three else 'four'}-layer {size.split('-', 1)[1]} ({weights} w)"
        left.errorbar(load, held[:, 0], yerr=[held[:, 0] - held[:, 1], held[:, 2] - held[:, 0]],
                      fmt="o" + style, color=color, capsize=2, ms=4, label=label)
        right.plot(load, [np.nanmean(c["fitness"]) for c in mine], "o" + style, color=color,
                   ms=4, label=label)
        for ax, ys in ((left, held[:, 0]), (right, [np.nanmean(c["fitness"]) for c in mine])):
            paper = [i for i, c in enumerate(mine) if c["cell"].endswith("-p2")
                     or (size == "four-2-2-4" and c["cell"].endswith("L10.24"))]
            ax.plot([load[i] for i in paper], [ys[i] for i in paper], "o", ms=11, mfc="none",
                    color=color)
    for ax, title in ((left, "share of runs that hold (<= 1 separation per reach), 95% exact "
                       "CI"), (right, "late top-20 fitness, mean over seeds")):
        ax.set_xscale("log", base=2)
        ax.set_xlabel("bit flips per copy (weights x 8 bits x flip rate)")
        ax.set_title(title, fontsize=9)
    left.set_ylim(-0.05, 1.05)
    right.legend(fontsize=7)
    fig.suptitle("Holding against mutational load (H3; ringed: the paper's 2% flip rate)",
                 fontsize=10)
    return save(fig, folder / LOAD_MAP, dpi=90)


EXPERIMENTS = "experiments_e1.png"


def experiments_figure(panels: list[tuple[str, bool, list[dict]]], folder: Path) -> Path | None:
    """E1's figure: per cell the share of runs that hold (exact 95% interval) against the
    weights, one marker per width of the last hidden layer (three-layer anchors hollow), or
    against the weight range; None without panels. A panel: (title, by weight range, the runs
    as experiments.runs_of gives them)."""
    if not panels:
        return None
    folder.mkdir(parents=True, exist_ok=True)
    fig, axes = plt.subplots(1, len(panels), figsize=(6.2 * len(panels), 4.6), squeeze=False)
    for ax, (title, by_range, runs) in zip(axes.flat, panels):
        cells = {}
        for r in runs:
            cells.setdefault(r["cell"], []).append(r)
        widths = sorted({rs[0]["width"] for rs in cells.values()})
        markers = dict(zip(widths, "os^Dv<>ph*"))
        for name, rs in cells.items():
            held = share([r["holds"] for r in rs])
            first = rs[0]
            x = first["range"] if by_range else first["weights"] * (1.03 if first["three_layer"]
                                                                   else 1.0)
            color = plt.cm.tab10(widths.index(first["width"]) % 10)
            ax.errorbar([x], [held.mean], yerr=[[held.mean - held.lo], [held.hi - held.mean]],
                        fmt=markers[first["width"]], color=color, capsize=2, ms=6,
                        mfc="none" if first["three_layer"] else color)
            ax.annotate(name, (x, held.mean), fontsize=6, xytext=(4, 3),
                        textcoords="offset points")
        for width in widths:
            ax.plot([], [], markers[width], color=plt.cm.tab10(widths.index(width) % 10),
                    label=f"width {width:g}")
        ax.set_xscale("log", base=2)
        ax.set_xlabel("weight range R (weights in [-R, R])" if by_range
                      else "weights (hollow: three-layer)")
        ax.set_ylim(-0.05, 1.05)
        ax.set_title(f"{title}: share of runs that hold, 95% exact CI", fontsize=9)
        ax.legend(fontsize=7)
    return save(fig, folder / EXPERIMENTS, dpi=90)

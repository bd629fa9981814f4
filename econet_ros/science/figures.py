"""The paper's Figures 3-9 redrawn from a study, plus the lesion test, the sensitivity variants
and a gallery of hand paths: one function per figure, each returning a matplotlib Figure;
make_figures writes them as PNG files. Curves are the mean over runs with a ±1 s.d. band, and
every run's own curve as a thin line. ROS-free."""
from __future__ import annotations

import itertools
from pathlib import Path

import matplotlib

matplotlib.use("Agg")     # files only, never a window
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..files import writing  # noqa: E402
from ..run_folders import RunData  # noqa: E402
from ..runs import replay  # noqa: E402
from .lesion import LESION_TRIALS  # noqa: E402
from .measures import CHANCE, body_frame, reach_starts  # noqa: E402
from .series import nanmean, nanstd, per_run  # noqa: E402
from .study import ConditionData  # noqa: E402

COLORS = {"normal": "tab:blue", "three-layer": "tab:orange", "random": "tab:gray"}
VARIANT_COLORS = ["tab:blue", "tab:green", "tab:purple", "tab:brown", "tab:olive"]
WORKSPACE = 55            # half-width of the lesion panels (workspace units)


def make_figures(groups: dict[str, dict[str, ConditionData]], lesion: list[dict],
                 folder: Path, more=()) -> dict[str, Path]:
    """Write every figure the study allows, and the (name, figure) pairs of ``more``, into
    folder; returns {name: PNG path}."""
    folder.mkdir(parents=True, exist_ok=True)
    return {name: save(fig, folder / f"{name}.png")
            for name, fig in itertools.chain(_drawings(groups, lesion), more)}


def _drawings(groups, lesion):
    """(name, figure) pairs, each figure drawn only when the previous one is saved."""
    base = groups["base"]
    normal, random = base.get("normal"), base.get("random")
    yield "fig3_performance", performance(base)
    yield "fig4_shoulder_flexion", flexion_per_run(normal, "shoulder", 4)
    yield "fig5_elbow_flexion", flexion_per_run(normal, "elbow", 5)
    yield "fig6_activation_space", activation_space()
    yield "fig7_coactivation", coactivation(normal)
    yield "fig8_approach", approach(normal, random)
    yield "fig9_speed", speed(normal, random)
    runs = [(condition, data.run_dirs[0]) for condition, data in base.items() if _has_runs(data)]
    if runs:
        yield "gallery", hand_path_gallery(runs)
    if lesion:
        yield "lesion", lesion_reaches(lesion)
    if len(groups) > 1:
        yield "sensitivity", sensitivity(groups)


def save(fig, path: Path, dpi: int = 110) -> Path:
    """Lay the figure out, write it (a full disk or a read-only folder: one line) and close it."""
    fig.tight_layout()
    with writing(path):
        fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path


def _has_runs(data: ConditionData | None) -> bool:
    return data is not None and data.n_runs > 0


def series(data: ConditionData, column: str) -> np.ndarray:
    """(runs, G) values of a column, or of the ratio "a/b" of two (per generation)."""
    if "/" not in column:
        return per_run(data, column)
    top, below = (per_run(data, c) for c in column.split("/"))
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(below > 0, top / below, np.nan)


def band(ax, data: ConditionData | None, column: str, label: str, color: str,
         style: str = "-", runs: bool = True) -> None:
    """A column's mean curve over runs with a ±1 s.d. band and, with runs, each run's curve
    as a thin line; nothing for a condition without runs."""
    if not _has_runs(data):
        return
    values = series(data, column)
    mean, sd = nanmean(values, axis=0), nanstd(values, axis=0)
    x = np.arange(values.shape[1])
    if runs:
        for run in values:
            ax.plot(x, run, style, color=color, lw=0.4, alpha=0.3)
    ax.plot(x, mean, style, color=color, label=f"{label} (N={data.n_runs})", lw=1.4)
    ax.fill_between(x, mean - sd, mean + sd, color=color, alpha=0.15, lw=0)


PERFORMANCE_PANELS = [("fitness", "(a) fitness"), ("successes", "(b) successful trials"),
                      ("latency", "(c) latency (a miss counts as the trial length)"),
                      ("separations", "(d) separations")]


def performance(base: dict[str, ConditionData]):
    """Figure 3: top-20 fitness, successes, latency and separations of every condition, with
    the whole population's mean (dotted); and two views the paper does not show: latency over
    successful trials only, and separations per successful trial."""
    fig, axes = plt.subplots(2, 3, figsize=(14, 7))
    panels = list(zip(axes.ravel()[[0, 1, 3, 4]], PERFORMANCE_PANELS))
    for ax, (measure, title) in panels:
        for condition, data in base.items():
            band(ax, data, f"top_{measure}", f"{condition}, top 20", COLORS[condition])
            band(ax, data, f"all_{measure}", f"{condition}, all", COLORS[condition], ":",
                 runs=False)
        ax.set_title(title)
    for ax, column, title in ((axes[0, 2], "top_latency_success",
                               "(c') latency over successful trials only"),
                              (axes[1, 2], "top_separations/top_successes",
                               "(d') separations per successful trial")):
        for condition, data in base.items():
            band(ax, data, column, condition, COLORS[condition])
        ax.set_title(title)
    for ax in axes.ravel():
        ax.set_xlabel("generation")
    axes[0, 0].legend(fontsize=7)
    fig.suptitle("Figure 3: performance per generation (top 20 solid, all econets dotted; "
                 "mean ± 1 s.d. over runs, thin lines: each run)")
    return fig


def flexion_per_run(normal: ConditionData | None, joint: str, number: int):
    """Figures 4 and 5: a joint's flexion % per normal run, one panel a run."""
    values = per_run(normal, f"all_{joint}_flexion") if _has_runs(normal) else []
    n = max(1, len(values))
    cols = min(5, n)
    rows = int(np.ceil(n / cols))
    fig, axes = plt.subplots(rows, cols, figsize=(2.4 * cols, 2.0 * rows + 0.6),
                             sharex=True, sharey=True, squeeze=False)
    for i, ax in enumerate(axes.ravel()):
        if i >= len(values):
            ax.axis("off")
            continue
        ax.plot(values[i], color="tab:blue", lw=1)
        ax.axhline(50, color="k", lw=0.5, ls=":")
        ax.set_ylim(-3, 103)
        ax.set_title(normal.run_dirs[i].name.replace("run-", "run "), fontsize=9)
    fig.suptitle(f"Figure {number}: % of pre-contact cycles with {joint} flexion "
                 "(flexor > extensor), all econets")
    return fig


def activation_space():
    """Figure 6: the two ideal patterns in (flexor, extensor) space and the deviations of one
    example point from them."""
    fig, ax = plt.subplots(figsize=(4.2, 4.2))
    ax.plot([0, 1], [0, 1], "g-", label="ideal coactivation (f = e)")
    ax.plot([0, 1], [1, 0], "r-", label="ideal reciprocal (f + e = 1)")
    f, e = 0.8, 0.45
    ax.plot([f], [e], "ko")
    ax.plot([f, (f + e) / 2], [e, (f + e) / 2], "g--")
    ax.plot([f, (f - e + 1) / 2], [e, (e - f + 1) / 2], "r--")
    ax.set_xlabel("flexor activation f")
    ax.set_ylabel("extensor activation e")
    ax.set_aspect("equal")
    ax.legend(fontsize=7, loc="upper left")
    ax.set_title("Figure 6: activation space")
    return fig


def coactivation(normal: ConditionData | None):
    """Figure 7: deviation from ideal coactivation and reciprocal activation per joint; below,
    the coactivation split into co-contraction (both muscles high) and co-relaxation (both
    low)."""
    fig, axes = plt.subplots(2, 2, figsize=(10, 7.4), sharex=True)
    for col, joint, tag in zip(range(2), ("shoulder", "elbow"), ("(a)", "(b)")):
        band(axes[0, col], normal, f"top_{joint}_coact", "coactivation", "tab:green")
        band(axes[0, col], normal, f"top_{joint}_recip", "reciprocal", "tab:red")
        axes[0, col].set_title(f"{tag} {joint}: mean deviation from ideal pattern")
        band(axes[1, col], normal, f"top_{joint}_cocontraction", "both > 0.5 (co-contraction)",
             "tab:purple")
        band(axes[1, col], normal, f"top_{joint}_corelaxation", "both < 0.5 (co-relaxation)",
             "tab:olive")
        axes[1, col].set_title(f"{joint}: share of cycles")
        axes[1, col].set_xlabel("generation")
        for ax in axes[:, col]:
            ax.legend(fontsize=7)
    fig.suptitle("Figure 7: deviation from ideal coactivation / reciprocal activation, "
                 "top 20, before first contact (thin lines: each run)")
    return fig


def approach(normal: ConditionData | None, random: ConditionData | None):
    """Figure 8: P(approach) with and without fixation, against chance: random movement's,
    with and without fixation (what the claims compare with), and the paper's 0.5 (dotted)."""
    fig, ax = plt.subplots(figsize=(7, 4))
    band(ax, normal, "top_approach_fix", "normal, fixation", "tab:blue")
    band(ax, normal, "top_approach_nofix", "normal, non-fixation", "tab:cyan", "--")
    band(ax, random, "top_approach_fix", "random, fixation", "tab:gray")
    band(ax, random, "top_approach_nofix", "random, non-fixation", "tab:gray", "--", runs=False)
    ax.axhline(CHANCE, color="k", lw=0.6, ls=":")
    ax.set_xlabel("generation")
    ax.set_ylabel("P(approach movement)")
    ax.legend(fontsize=8)
    ax.set_title("Figure 8: probability of an approach movement (top 20, pre-contact)")
    return fig


def speed(normal: ConditionData | None, random: ConditionData | None):
    """Figure 9: hand and head/eye speed while the object is fixated."""
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
    for ax, kind, tag, unit in ((axes[0], "hand", "(a) hand", "units/cycle"),
                                (axes[1], "eye", "(b) head/eye", "deg/cycle")):
        band(ax, normal, f"top_{kind}_speed_fix", "normal", "tab:blue")
        band(ax, random, f"top_{kind}_speed_fix", "random", "tab:gray")
        ax.set_title(f"{tag} speed during fixation")
        ax.set_ylabel(unit)
        ax.set_xlabel("generation")
        ax.legend(fontsize=8)
    fig.suptitle("Figure 9: movement speed while the object is fixated (top 20, pre-contact)")
    return fig


def lesion_reaches(lesion: list[dict]):
    """The lesion test, intact vs lesioned: the first run's hand paths, and where every run's
    reaches start (body frame)."""
    fig, axes = plt.subplots(2, 2, figsize=(9, 9))
    for col, kind in enumerate(("intact", "lesioned")):
        _hand_paths(axes[0, col], lesion[0], kind)
        _reach_starts(axes[1, col], lesion, kind)
    fig.suptitle("Proprioceptive lesion: final top-20 econets of every normal run")
    return fig


def _hand_paths(ax, run: dict, kind: str) -> None:
    """Hand paths to first contact of the run's best econet in its first 10 trials."""
    trace = run["traces"][kind]
    for env in range(min(LESION_TRIALS, 10)):
        touch = trace.touch[:, env]
        stop = int(np.argmax(touch)) if touch.any() else trace.touch.shape[0] - 1
        path = trace.hand[:stop + 1, env]
        ax.plot(path[:, 0], path[:, 1], "-", lw=0.8)
        ax.plot(*path[0], "k.", ms=4)
        ax.add_patch(plt.Circle(trace.object_xy[env], run["radius"], color="r", alpha=0.6))
    _workspace(ax, f"{kind}: hand paths to first contact\n({run['run']}, best econet, "
               "10 trials)")


def _reach_starts(ax, lesion: list[dict], kind: str) -> None:
    for run in lesion:
        trace = run["traces"][kind]
        starts, valid = reach_starts(trace)
        envs = np.flatnonzero(valid)
        if len(envs):
            points = body_frame(trace, starts[envs], envs)
            ax.plot(points[:, 0], points[:, 1], ".", ms=2, alpha=0.4)
    _workspace(ax, f"{kind}: reach-start hand positions, body frame\n(gaze along +x; "
               "colour = run)")


def _workspace(ax, title: str) -> None:
    """The shoulder at the origin, equal axes over the workspace."""
    ax.plot(0, 0, "k+", ms=10)
    ax.set_aspect("equal")
    ax.set_xlim(-WORKSPACE, WORKSPACE)
    ax.set_ylim(-WORKSPACE, WORKSPACE)
    ax.set_title(title, fontsize=9)


def sensitivity(groups: dict[str, dict[str, ConditionData]]):
    """Fitness and P(approach | fixated) of the normal condition (and the three-layer one where
    a variant re-ran it) under the base settings and every variant."""
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
    for i, (name, group) in enumerate(groups.items()):
        color = VARIANT_COLORS[i % len(VARIANT_COLORS)]
        band(axes[0], group.get("normal"), "top_fitness", f"normal, {name}", color)
        band(axes[1], group.get("normal"), "top_approach_fix", f"normal, {name}", color)
        if name != "base":
            band(axes[0], group.get("three-layer"), "top_fitness", f"three-layer, {name}",
                 color, "--")
    axes[0].set_title("top-20 fitness")
    axes[1].set_title("P(approach | fixated)")
    axes[1].axhline(CHANCE, color="k", lw=0.6, ls=":")
    for ax in axes:
        ax.set_xlabel("generation")
        ax.legend(fontsize=7)
    fig.suptitle("Sensitivity: base assumptions vs variants")
    return fig


GALLERY_TRIALS = 6


def hand_path_gallery(runs: list[tuple[str, Path]], trials: int = GALLERY_TRIALS):
    """For each (label, run folder): the best econet's hand paths in its first trials, early
    (generation G/10) and late (the last generation), the whole trial long; a reaching econet
    draws lines that end on the object, a spinning one circles round the body."""
    fig, axes = plt.subplots(len(runs), 2, figsize=(7.6, 3.9 * len(runs)), squeeze=False)
    for row, (label, folder) in enumerate(runs):
        data = RunData(folder)
        last = data.generations_done - 1
        for col, generation in enumerate((min(last, max(0, data.config.evolution.generations
                                                         // 10 - 1)), last)):
            _best_paths(axes[row, col], replay(folder, generation), data, trials)
            axes[row, col].set_title(f"{label}, {folder.name}, generation {generation}",
                                     fontsize=9)
    fig.suptitle(f"Hand paths of the best econet, {trials} trials each (dot: start, cross: "
                 "end; object red)", fontsize=10)
    return fig


def _best_paths(ax, result, data: RunData, trials: int) -> None:
    best = int(result.parents[0])
    per_econet = data.config.evolution.trials
    trace = result.trace
    for k, env in enumerate(range(best * per_econet, best * per_econet + min(trials,
                                                                            per_econet))):
        path = trace.hand[:, env]
        color = plt.cm.tab10(k)
        ax.plot(path[:, 0], path[:, 1], "-", color=color, lw=0.7)
        ax.plot(*path[0], "o", color=color, ms=3)
        ax.plot(*path[-1], "x", color=color, ms=5)
        ax.add_patch(plt.Circle(trace.object_xy[env], data.config.model.object_radius,
                                color="r", alpha=0.7))
    _workspace(ax, "")

"""Figures and the Markdown report of a study folder (see study.py): every claim of the paper's
Results section (claims.py) next to our measurement and a verdict. Definitions: docs/analysis.md."""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from .claims import LOCK, VERDICTS, ClaimResult, evaluate, joint_table
from .lesion import LESION_TRIALS, lesion_study
from .measures import CHANCE
from .series import Windows, fmt, mean_sd, nanmean, nanstd, per_run
from .study import ConditionData, StudySpec, load_study

COLORS = {"normal": "tab:blue", "three-layer": "tab:orange", "random": "tab:gray"}


# -- figures ------------------------------------------------------------------------------------------
def _band(ax, data: ConditionData, column: str, label: str, color: str,
          style: str = "-") -> None:
    if data is None or not data.n_runs:
        return
    values = per_run(data, column)
    if not len(values):
        return
    mean, sd = nanmean(values, axis=0), nanstd(values, axis=0)
    x = np.arange(values.shape[1])
    ax.plot(x, mean, style, color=color, label=f"{label} (N={data.n_runs})", lw=1.3)
    ax.fill_between(x, mean - sd, mean + sd, color=color, alpha=0.18, lw=0)


def make_figures(groups, lesion, figures: Path, G: int) -> dict[str, str]:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figures.mkdir(parents=True, exist_ok=True)
    base = groups["base"]
    N, R = base.get("normal"), base.get("random")
    files = {}

    def save(fig, name):
        fig.tight_layout()
        path = figures / f"{name}.png"
        fig.savefig(path, dpi=110)
        plt.close(fig)
        files[name] = path

    # Figure 3
    fig, axes = plt.subplots(2, 2, figsize=(10, 7))
    panels = [("top_fitness", "(a) fitness"), ("top_successes", "(b) successful trials"),
              ("top_latency", "(c) latency (cycles)"), ("top_separations", "(d) separations")]
    for ax, (col, title) in zip(axes.ravel(), panels):
        for cond, d in base.items():
            if d.n_runs:
                _band(ax, d, col, cond, COLORS[cond])
        ax.set_title(title)
        ax.set_xlabel("generation")
    axes[0, 0].legend(fontsize=8)
    fig.suptitle("Figure 3: top-20 performance per generation (mean ± 1 s.d. over runs)")
    save(fig, "fig3_performance")

    # Figures 4 and 5
    for joint, name, num in (("shoulder", "fig4_shoulder_flexion", 4),
                             ("elbow", "fig5_elbow_flexion", 5)):
        values = (per_run(N, f"all_{joint}_flexion") if N is not None and N.n_runs
                  else np.zeros((0, G)))
        n = max(1, values.shape[0])
        cols = min(5, n)
        rows = int(np.ceil(n / cols))
        fig, axes = plt.subplots(rows, cols, figsize=(2.4 * cols, 2.0 * rows + 0.6),
                                 sharex=True, sharey=True, squeeze=False)
        for i, ax in enumerate(axes.ravel()):
            if i >= values.shape[0]:
                ax.axis("off")
                continue
            ax.plot(values[i], color="tab:blue", lw=1)
            ax.axhline(50, color="k", lw=0.5, ls=":")
            ax.set_ylim(-3, 103)
            ax.set_title(N.run_dirs[i].name.replace("run-", "run "), fontsize=9)
        fig.suptitle(f"Figure {num}: % of pre-contact cycles with {joint} flexion "
                     "(flexor > extensor), all econets")
        save(fig, name)

    # Figure 7 (and 6: the activation space schematic with our final-generation means)
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8), sharey=True)
    for ax, joint, tag in zip(axes, ("shoulder", "elbow"), ("(a)", "(b)")):
        _band(ax, N, f"top_{joint}_coact", "coactivation", "tab:green")
        _band(ax, N, f"top_{joint}_recip", "reciprocal", "tab:red")
        ax.set_title(f"{tag} {joint}: mean deviation from ideal pattern")
        ax.set_xlabel("generation")
        ax.legend(fontsize=8)
    fig.suptitle("Figure 7: deviation from ideal coactivation / reciprocal activation, "
                 "top 20, before first contact")
    save(fig, "fig7_coactivation")

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
    save(fig, "fig6_activation_space")

    # Figure 8
    fig, ax = plt.subplots(figsize=(7, 4))
    _band(ax, N, "top_approach_fix", "normal, fixation", "tab:blue")
    _band(ax, N, "top_approach_nofix", "normal, non-fixation", "tab:cyan", "--")
    if R is not None and R.n_runs:
        _band(ax, R, "top_approach_fix", "random, fixation", "tab:gray")
    ax.axhline(CHANCE, color="k", lw=0.6, ls=":")
    ax.set_xlabel("generation")
    ax.set_ylabel("P(approach movement)")
    ax.legend(fontsize=8)
    ax.set_title("Figure 8: probability of an approach movement (top 20, pre-contact)")
    save(fig, "fig8_approach")

    # Figure 9
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
    for ax, kind, tag, unit in ((axes[0], "hand", "(a) hand", "units/cycle"),
                                (axes[1], "eye", "(b) head/eye", "deg/cycle")):
        _band(ax, N, f"top_{kind}_speed_fix", "normal", "tab:blue")
        if R is not None and R.n_runs:
            _band(ax, R, f"top_{kind}_speed_fix", "random", "tab:gray")
        ax.set_title(f"{tag} speed during fixation")
        ax.set_ylabel(unit)
        ax.set_xlabel("generation")
        ax.legend(fontsize=8)
    fig.suptitle("Figure 9: movement speed while the object is fixated (top 20, pre-contact)")
    save(fig, "fig9_speed")

    # Lesion
    if lesion:
        fig, axes = plt.subplots(2, 2, figsize=(9, 9))
        first = lesion[0]
        for col, kind in enumerate(("intact", "lesioned")):
            tr = first["traces"][kind]
            ax = axes[0, col]
            for env in range(min(LESION_TRIALS, 10)):    # the best econet's first trials
                stop = int(np.argmax(tr.touch[:, env])) if tr.touch[:, env].any() else \
                    tr.touch.shape[0] - 1
                path = tr.hand[:stop + 1, env]
                ax.plot(path[:, 0], path[:, 1], "-", lw=0.8)
                ax.plot(*path[0], "k.", ms=4)
                ax.add_patch(plt.Circle(tr.object_xy[env], first["radius"], color="r",
                                        alpha=0.6))
            ax.plot(0, 0, "k+", ms=10)
            ax.set_aspect("equal")
            ax.set_xlim(-55, 55)
            ax.set_ylim(-55, 55)
            ax.set_title(f"{kind}: hand paths to first contact\n({first['run']}, best econet, "
                         "10 trials)", fontsize=9)
            from .measures import body_frame, reach_starts
            ax = axes[1, col]
            for item in lesion:
                t = item["traces"][kind]
                starts, valid = reach_starts(t)
                envs = np.flatnonzero(valid)
                if len(envs):
                    pts = body_frame(t, starts[envs], envs)
                    ax.plot(pts[:, 0], pts[:, 1], ".", ms=2, alpha=0.4)
            ax.plot(0, 0, "k+", ms=10)
            ax.set_aspect("equal")
            ax.set_xlim(-55, 55)
            ax.set_ylim(-55, 55)
            ax.set_title(f"{kind}: reach-start hand positions, body frame\n(gaze along +x; "
                         "colour = run)", fontsize=9)
        fig.suptitle("Proprioceptive lesion: final top-20 econets of every normal run")
        save(fig, "lesion")

    # Sensitivity: fitness of the normal condition per variant
    if len(groups) > 1:
        fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
        palette = ["tab:blue", "tab:green", "tab:purple", "tab:brown", "tab:olive"]
        for i, (name, group) in enumerate(groups.items()):
            d = group.get("normal")
            if d is not None and d.n_runs:
                _band(axes[0], d, "top_fitness", f"normal, {name}", palette[i % 5])
                _band(axes[1], d, "top_approach_fix", f"normal, {name}", palette[i % 5])
            if name != "base" and "three-layer" in group and group["three-layer"].n_runs:
                _band(axes[0], group["three-layer"], "top_fitness", f"three-layer, {name}",
                      palette[i % 5], "--")
        axes[0].set_title("top-20 fitness")
        axes[1].set_title("P(approach | fixated)")
        axes[1].axhline(CHANCE, color="k", lw=0.6, ls=":")
        for ax in axes:
            ax.set_xlabel("generation")
            ax.legend(fontsize=7)
        fig.suptitle("Sensitivity: base assumptions vs variants")
        save(fig, "sensitivity")
    return files


# -- the report -----------------------------------------------------------------------------------------
def build_report(out: Path, report: Path | None = None, figures: Path | None = None
                 ) -> tuple[Path, list[str]]:
    """Analyse a study folder and write the report and figures; returns (report path, notes
    about gaps). Raises study.StudyError for folders that cannot be analysed."""
    out = Path(out)
    spec, groups = load_study(out)
    report = Path(report) if report else out / "report.md"
    figures = Path(figures) if figures else report.parent / "figures"
    report.parent.mkdir(parents=True, exist_ok=True)
    G = spec.config.evolution.generations

    notes = []
    for gname, group in groups.items():
        for cond, d in group.items():
            for p in d.problems:
                notes.append(f"{'' if gname == 'base' else gname + ' / '}{cond}: {p}")
    lesions = {name: lesion_study(group["normal"].run_dirs) if "normal" in group else []
               for name, group in groups.items()}
    claims = {}
    for name, group in groups.items():
        merged = dict(groups["base"])
        merged.update(group)
        claims[name] = evaluate(merged, lesions[name], G)
    files = make_figures(groups, lesions["base"], figures, G)
    rel = {k: os.path.relpath(v, report.parent) for k, v in files.items()}
    report.write_text(_markdown(spec, groups, claims, lesions, notes, rel, G, out),
                      encoding="utf-8")
    return report, notes


def _markdown(spec: StudySpec, groups, claims, lesions, notes, figs, G, out) -> str:
    e, net, m = spec.config.evolution, spec.config.network, spec.config.model
    base = groups["base"]
    L = []
    L.append("# Reproducing Schlesinger, Parisi & Langer (2000): results report\n")
    L.append(f"Made by `econet analyze {out}` from the study folder `{out}` "
             f"(`econet study` = `scripts/run`). Measures are defined in "
             "`docs/analysis.md`; the model's assumptions in `docs/assumptions.md`.\n")
    L.append("## Settings\n")
    L.append(f"- {spec.runs} runs per condition, {G} generations, population {e.population}, "
             f"{e.parents} parents, {e.trials} trials x {e.cycles} cycles, base seed {spec.seed}")
    L.append(f"- four-layer hidden sizes {net.visual_hidden} (visual) / {net.proprio_hidden} "
             f"(proprioceptive) / {net.intermodal_hidden} (intermodal); three-layer hidden "
             f"{net.three_layer_hidden}; object radius {m.object_radius:g}; start posture "
             f"{m.start_posture}; mutation {e.mutation_mode} {e.mutation_rate:g}")
    L.append("- all curves: mean over runs, band = ±1 s.d. over runs; top 20 = the econets "
             "selected for reproduction in that generation\n")
    L.append("## Completeness\n")
    if notes:
        L.append("**This study is incomplete; every number below uses only the data present.** "
                 "Gaps:\n")
        L.extend(f"- {n}" for n in notes)
        L.append("\nRun the same `econet study` command again to finish it.\n")
    else:
        L.append("All runs of all conditions are complete.\n")
    counts = ", ".join(f"{c}: {d.n_runs} runs" for c, d in base.items())
    L.append(f"Runs found: {counts}.\n")

    L.append("## Claims of the paper's Results section vs our measurements\n")
    L.append(_claims_table(claims["base"]))
    tally = {v: sum(c.verdict == v for c in claims["base"]) for v in VERDICTS}
    L.append("\nTally: " + ", ".join(f"{k} {v}" for k, v in tally.items()) + ".\n")

    L.append("## Overall performance (Figure 3)\n")
    L.append(f"![Figure 3]({figs['fig3_performance']})\n")
    L.append("## 1 Joint locking (Figures 4 and 5)\n")
    L.append(f"![Figure 4]({figs['fig4_shoulder_flexion']})\n")
    L.append(f"![Figure 5]({figs['fig5_elbow_flexion']})\n")
    w = Windows(G)
    L.append(f"Per run, {w.label(w.final)}, all econets, cycles before first contact "
             f"(locked = flexion <= {LOCK:.0f}% or >= {100 - LOCK:.0f}%; position from the mean "
             "shoulder angle: >= 135 deg extended, <= 45 deg flexed):\n")
    L.append("| run | shoulder flexion % | shoulder angle (deg) | shoulder | locked from gen | "
             "elbow flexion % | elbow |")
    L.append("|---|---|---|---|---|---|---|")
    if "normal" in base and base["normal"].n_runs:
        for r in joint_table(base["normal"], w):
            L.append(f"| {r['run']} | {fmt(r['shoulder_flexion'], 1)} | "
                     f"{fmt(r['shoulder_angle'], 0)} | {r['position']} | "
                     f"{fmt(r['lock_generation'], 0)} | {fmt(r['elbow_flexion'], 1)} | "
                     f"{'compliant' if r['elbow_compliant'] else 'dominated'} |")
    L.append("")
    L.append("## 2 Muscle coactivation (Figures 6 and 7)\n")
    L.append(f"![Figure 6]({figs['fig6_activation_space']})\n")
    L.append(f"![Figure 7]({figs['fig7_coactivation']})\n")
    L.append("## 3 Stereotyped approach movements and the lesion (Figure 8)\n")
    L.append(f"![Figure 8]({figs['fig8_approach']})\n")
    if "lesion" in figs:
        L.append(f"![Lesion]({figs['lesion']})\n")
    L.append(_lesion_table(lesions["base"]))
    L.append("## 4 Movement slowdown (Figure 9)\n")
    L.append(f"![Figure 9]({figs['fig9_speed']})\n")

    L.append("## Sensitivity to the paper's open assumptions\n")
    if len(groups) == 1:
        L.append("No sensitivity variants in this study (run `econet study --sensitivity all` "
                 "to add them).\n")
    else:
        L.append("Each variant re-runs the conditions its setting affects, with the same seeds; "
                 "conditions it does not affect are taken from the base study (random movement "
                 "ignores network sizes; the three-layer net ignores the four-layer hidden "
                 "sizes).\n")
        for name, changes in spec.variants.items():
            setting = ", ".join(f"{k}={v}" for k, v in changes.items())
            ran = ", ".join(f"{c} ({d.n_runs} runs)" for c, d in groups[name].items())
            gaps = [p for d in groups[name].values() for p in d.problems]
            L.append(f"- **{name}**: {setting}; ran {ran}"
                     + (f"; INCOMPLETE: {'; '.join(gaps)}" if gaps else ""))
        L.append("")
        names = list(groups)
        L.append("| claim | " + " | ".join(names) + " |")
        L.append("|---|" + "---|" * len(names))
        for i, c in enumerate(claims["base"]):
            L.append(f"| {c.claim.key} | " + " | ".join(claims[n][i].verdict for n in names) + " |")
        L.append("")
        robust = [c.claim.key for i, c in enumerate(claims["base"])
                  if len({claims[n][i].verdict for n in names}) == 1]
        fragile = [c.claim.key for i, c in enumerate(claims["base"])
                   if len({claims[n][i].verdict for n in names}) > 1]
        L.append(f"Same verdict under every setting: {', '.join(robust) or 'none'}.\n")
        L.append(f"Verdict depends on the setting: {', '.join(fragile) or 'none'}.\n")
        if "sensitivity" in figs:
            L.append(f"![Sensitivity]({figs['sensitivity']})\n")
        for name in names[1:]:
            L.append(f"<details><summary>{name}: measurements</summary>\n")
            L.append(_claims_table(claims[name]))
            L.append("\n</details>\n")
    return "\n".join(L) + "\n"


def _claims_table(claims: list[ClaimResult]) -> str:
    rows = ["| # | section | paper's claim | our measurement | verdict |",
            "|---|---|---|---|---|"]
    for i, c in enumerate(claims, 1):
        rows.append(f"| {i} | {c.claim.section} | {c.claim.paper} | {c.ours.replace('|', '/')} | "
                    f"**{c.verdict}** |")
    return "\n".join(rows) + "\n"


def _lesion_table(lesion: list[dict]) -> str:
    if not lesion:
        return "No normal runs: no lesion test.\n"
    fields = [("success_rate", "success rate", 2), ("latency", "latency (cycles)", 1),
              ("approach_prob", "P(approach), pre-contact", 2),
              ("path_efficiency", "path efficiency", 2), ("turning", "turning (deg/cycle)", 1),
              ("final_approach_cycles", "final approach (cycles)", 1),
              ("start_spread_body", "reach-start spread, body frame", 1),
              ("start_spread_world", "reach-start spread, workspace", 1),
              ("start_radius", "reach-start distance from shoulder", 1)]
    rows = [f"Final-generation top-20 econets of {len(lesion)} normal runs, {LESION_TRIALS} fresh "
            "trials each, intact vs proprioceptive inputs severed (mean ± s.d. over runs):\n",
            "| measure | intact | lesioned |", "|---|---|---|"]
    for attr, label, digits in fields:
        a = [getattr(r["intact"], attr) for r in lesion]
        b = [getattr(r["lesioned"], attr) for r in lesion]
        rows.append(f"| {label} | {mean_sd(a, digits)} | {mean_sd(b, digits)} |")
    return "\n".join(rows) + "\n"

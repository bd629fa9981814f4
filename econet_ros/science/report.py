"""The Markdown report of a study folder (see study.py): every claim of the paper's Results
section (claims.py) next to our measurement and a verdict, with the figures (figures.py).
Definitions: docs/analysis.md."""
from __future__ import annotations

import os
from pathlib import Path

from .claims import LOCK, VERDICTS, ClaimResult, evaluate, joint_table
from .figures import make_figures
from .lesion import LESION_TRIALS, lesion_study
from .series import Windows, fmt, mean_sd
from .study import StudySpec, load_study


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
    files = make_figures(groups, lesions["base"], figures)
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

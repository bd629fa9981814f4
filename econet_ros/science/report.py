"""The Markdown report of a study folder (see study.py): every claim of the paper's Results
section (claims.py) next to our measurement and a verdict, with the figures (figures.py).
Definitions: docs/analysis.md."""
from __future__ import annotations

import csv
import dataclasses
import functools
import gzip
import io
import os
import shutil
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import UsageError
from ..files import ensure_writable, write_atomically
from ..provenance import dirty_warning, made_with
from . import holding
from .claims import LEVEL_LIKE, SHUFFLES, ClaimResult, evaluate
from .evidence import LOCK, Evidence, joint_table
from .figures import make_figures
from .lesion import LESION_TRIALS, lesion_study
from .measures import ReachSummary, shared_reaches
from .optimizer_study import Comparison
from .series import Windows, fmt
from .stats import bounded, estimate, median
from .study import ConditionData, StudySpec, load_study, optimizer_only, run_codes
from .sweeps.outcomes import tidy_rows
from .sweeps.report import build_sweep_report, holding_markdown
from .sweeps.rules import Swept, choose_defaults, rule_of
from .sweeps.spec import load_sweep
from .verdicts import CLAIM_VERDICTS, PREMISE_FAILS


@dataclass
class Analysis:
    """What the report shows about one study folder."""

    out: Path
    spec: StudySpec
    groups: dict[str, dict[str, ConditionData]]    # "base" and each sensitivity variant
    notes: list[str]                               # gaps of an incomplete study
    lesions: dict[str, list[dict]]                 # per group: lesion test of its normal runs
    claims: dict[str, list[ClaimResult]]           # per group
    figures: dict[str, str]                        # name -> path relative to the report
    sweeps: list[Path] = dataclasses.field(default_factory=list)   # summarised in the report
    folder: Path = Path(".")                                       # where the report is
    optimizers: Comparison | None = None           # the optimizer variants, when run
    moved_windows: dict[str, list[ClaimResult]] = dataclasses.field(default_factory=dict)
    # the base group's claims with the early or late window moved (Windows.moved)

    @property
    def windows(self) -> Windows:
        return Windows(self.spec.config.evolution.generations)

    @functools.cached_property
    def swept(self) -> list[Swept]:
        """Each summarised sweep's spec and tidy rows, read once, with where the report
        publishes its summary (publish_sweep)."""
        return [Swept(spec, tidy_rows(spec, folder),
                      os.path.relpath(self.folder / "sweeps" / spec.name, self.folder))
                for folder in self.sweeps for spec in [load_sweep(folder)]]


def report_paths(out: Path, report: Path | None = None, figures: Path | None = None
                 ) -> tuple[Path, Path]:
    """Where the report and its figures go (default: OUT/report.md and the report's
    folder/figures), checked to be writable: a bad path is refused before the work, not after."""
    report = Path(report) if report else Path(out) / "report.md"
    figures = Path(figures) if figures else report.parent / "figures"
    for folder in (report.parent, figures):
        ensure_writable(folder)
    if report.is_dir():
        raise UsageError(f"cannot write the report to {report}: it is a folder")
    return report, figures


def build_report(out: Path, report: Path | None = None, figures: Path | None = None,
                 sweeps: list[Path] = ()) -> tuple[Path, list[str]]:
    """Analyse a study folder and write the report and figures (with a section on each sweep
    folder given); returns (report path, notes about gaps). Raises ResultsError for a folder
    that cannot be analysed and UsageError for a report or figures folder that cannot be
    written, both before any work."""
    out = Path(out)
    spec, groups = load_study(out)
    report, figures = report_paths(out, report, figures)
    lesions = {name: lesion_study(group["normal"].run_dirs) if "normal" in group else []
               for name, group in groups.items()}
    windows = Windows(spec.config.evolution.generations)
    # a variant holds only the conditions it re-ran; the others come from the base study
    claims = {name: evaluate({**groups["base"], **group}, lesions[name], windows,
                             nulls=name == "base")
              for name, group in groups.items()}
    moved = {label: evaluate(groups["base"], lesions["base"], other)
             for label, other in windows.moved().items()}
    optimizers = Comparison.of(spec, groups, claims)
    # the optimizer variants have their own section; the sensitivity section is the others'
    kept = [name for name in groups if not optimizer_only(spec.variants.get(name))]
    sensitivity = {name: groups[name] for name in kept}
    files = make_figures(sensitivity, lesions["base"], figures,
                         optimizers.drawings() if optimizers else ())
    analysis = Analysis(out, spec, sensitivity, gaps(groups), lesions,
                        {name: claims[name] for name in kept},
                        {k: os.path.relpath(v, report.parent) for k, v in files.items()},
                        [Path(s) for s in sweeps], report.parent, optimizers, moved)
    for folder in analysis.sweeps:
        publish_sweep(folder, report.parent / "sweeps")
    write_atomically(report, markdown(analysis))
    write_claims_csv(report.with_name("claims.csv"), claims["base"], moved)
    write_tables(report.parent / "data" / "per_generation.csv.gz", groups)
    write_lesion_rows(report.parent / "data" / "lesion.csv", lesions["base"])
    return report, analysis.notes


SWEEP_FILES = ("summary.md", "outcomes.csv", "comparisons.csv")


def publish_sweep(folder: Path, into: Path) -> Path:
    """A sweep's report (econet sweep report: summary, tables, figures) copied beside the study
    report, so the published report links to files that are there."""
    build_sweep_report(folder)
    target = into / load_sweep(folder).name
    (target / "figures").mkdir(parents=True, exist_ok=True)
    for name in SWEEP_FILES:
        shutil.copyfile(folder / name, target / name)
    for figure in (folder / "figures").glob("*.png"):
        shutil.copyfile(figure, target / "figures" / figure.name)
    return target


def write_tables(path: Path, groups: dict[str, dict[str, ConditionData]]) -> None:
    """Every run's per-generation metrics and behaviour as one tidy, compressed CSV (a row per
    group, condition, run and generation), so anyone can re-analyse without re-running."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with gzip.GzipFile(path, "wb", mtime=0) as raw, \
            io.TextIOWrapper(raw, encoding="utf-8", newline="") as handle:   # same bytes each time
        writer = None
        for name, group in groups.items():
            for condition, data in group.items():
                columns = {**data.metrics, **data.behaviour}
                if writer is None:
                    writer = csv.writer(handle)
                    writer.writerow(["group", "condition", "run", *columns])
                for i, folder in enumerate(data.run_dirs):
                    for g in range(data.done[i]):
                        writer.writerow([name, condition, folder.name,
                                         *(_cell(v[i, g]) for v in columns.values())])


def write_lesion_rows(path: Path, lesion: list[dict]) -> None:
    """The lesion test per run and kind (intact, lesioned, vision-lesioned): every measure the
    lesion claims read (measures.ReachSummary, its per-trial records left out), so the lesion's
    verdicts can be re-derived without re-running it."""
    fields = [f.name for f in dataclasses.fields(ReachSummary) if f.type != "tuple"]
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow(["run", "generation", "kind", *fields])
        writer.writerows([run["run"], run["generation"], kind,
                          *(_cell(getattr(run[kind], f)) for f in fields)]
                         for run in lesion for kind in LESIONS)


def _cell(value: float) -> str:
    return "" if not np.isfinite(value) else repr(float(value))


def gaps(groups: dict[str, dict[str, ConditionData]]) -> list[str]:
    """Every missing run or generation, named by variant and condition."""
    return [f"{'' if name == 'base' else name + ' / '}{condition}: {problem}"
            for name, group in groups.items() for condition, data in group.items()
            for problem in data.problems]


def markdown(analysis: Analysis) -> str:
    sections = (_title, _settings, _completeness, _regime, _holding, _architecture, _claims,
                _thresholds, _windows, _performance, _joint_locking, _coactivation, _approach,
                _slowdown, _sensitivity, _optimizers, _sweeps)
    return "\n".join(line for section in sections for line in section(analysis)) + "\n"


def _title(analysis: Analysis) -> list[str]:
    return [*dirty_warning(),
            "# Reproducing Schlesinger, Parisi & Langer (2000): results report\n",
            f"Made by `econet analyze {analysis.out}` from the study folder `{analysis.out}` "
            "(`econet study` = `scripts/run`). Measures are defined in "
            "`docs/analysis.md`; the model's assumptions in `docs/assumptions.md`.\n",
            made_with(run_codes(analysis.spec, analysis.out),
                      [sweep.registration() for sweep in analysis.swept]) + "\n"]


def _settings(analysis: Analysis) -> list[str]:
    config = analysis.spec.config
    e, net, m = config.evolution, config.network, config.model
    return ["## Settings\n",
            f"- {analysis.spec.runs} runs per condition, {e.generations} generations, population "
            f"{e.population}, {e.parents} parents, {e.trials} trials x {e.cycles} cycles, base "
            f"seed {analysis.spec.seed}",
            f"- four-layer hidden sizes {net.visual_hidden} (visual) / {net.proprio_hidden} "
            f"(proprioceptive) / {net.intermodal_hidden} (intermodal); three-layer hidden "
            f"{net.three_layer_hidden}; object radius {m.object_radius:g}; start posture "
            f"{m.start_posture}; mutation {e.mutation_mode} {e.mutation_rate:g}",
            "- all curves: mean over runs, band = ±1 s.d. over runs; top 20 = the econets "
            "selected for reproduction in that generation\n"]


def _completeness(analysis: Analysis) -> list[str]:
    if analysis.notes:
        status = ["**This study is incomplete; every number below uses only the data present.** "
                  "Gaps:\n", *(f"- {n}" for n in analysis.notes),
                  "\nRun the same `econet study` command again to finish it.\n"]
    else:
        status = ["All runs of all conditions are complete.\n"]
    counts = ", ".join(f"{c}: {d.n_runs} runs" for c, d in analysis.groups["base"].items())
    return ["## Completeness\n", *status, f"Runs found: {counts}.\n"]


def _regime(analysis: Analysis) -> list[str]:
    """Reaching or spinning? The diagnostics that tell the behaviour the paper analyses from
    the one our a-priori defaults produced."""
    ev = Evidence(analysis.groups["base"], [], analysis.windows)
    late = analysis.windows.final
    lines = ["## Regime: do the econets reach and hold, or spin and brush?\n",
             f"Late window ({analysis.windows.label(late)}), top 20, mean [95% CI] over runs; "
             "differences paired by run:\n"]
    for label, measure in REGIME_DIAGNOSTICS:
        try:
            lines.append(f"- {label}: {measure(ev, late)}")
        except ValueError as error:
            lines.append(f"- {label}: not measurable ({error})")
    if "gallery" in analysis.figures:
        lines.append(f"\n![Hand paths]({analysis.figures['gallery']})\n")
    return lines + [""]


def _against_random(column: str, digits: int):
    def measure(ev: Evidence, late: slice) -> str:
        pairs = {c: ev.compare((c, column, late), ("random", column, late))
                 for c in ("normal", "three-layer") if c in ev.group}
        return "; ".join(f"{c} - random {p.text(digits)}" for c, p in pairs.items())
    return measure


REGIME_DIAGNOSTICS = [
    ("successful trials against random movement", _against_random("top_successes", 2)),
    ("eye speed while the object is fixated, against random movement (deg/cycle; below "
     "random: sight of the object slows the eye; above: the eye spins past it)",
     _against_random("top_eye_speed_fix", 2)),
]


def _holding(analysis: Analysis) -> list[str]:
    """Hold or brush, per run: each run's late separations per successful trial and its class
    (holding.py, the threshold written down before the confirmatory study), the count of
    holding runs with its exact interval, medians beside means of the outcomes that split."""
    w = analysis.windows
    ev = Evidence(analysis.groups["base"], [], w)
    conditions = [c for c, data in ev.group.items() if data.n_runs]
    ratios = {c: ev.per_success(c, w.final) for c in conditions}
    runs = sorted(set().union(*ratios.values()))

    def cell(ratio: float | None) -> str:
        return "-" if ratio is None else f"{fmt(ratio, 2)} ({holding.kind(ratio)})"
    return ["## Hold or brush, per run\n",
            f"A run **holds** when its late ({w.label(w.final)}) top-20 separations per "
            f"successful trial (window sums) are at most {holding.LIMIT:g}, **brushes** above "
            "that, and **does not reach** without a successful trial (docs/analysis.md, "
            "'Holding, per run'). Outcomes split into holding and brushing runs, so medians "
            "(95% order-statistic interval) stand beside means (95% t interval, clipped at 0, "
            "below which none of these outcomes can lie); the claims judge these outcomes on "
            "medians.\n",
            "| condition | hold / brush / no reach | share holding [95% CI, Clopper-Pearson] | "
            "late separations per successful trial: mean; median | late top-20 fitness: "
            "mean; median | late successful trials: mean; median |", "|---|---|---|---|---|---|",
            *(_holding_row(ev, c, ratios[c]) for c in conditions), "",
            "| run | " + " | ".join(conditions) + " |", "|---|" + "---|" * len(conditions),
            *(f"| {run} | " + " | ".join(cell(ratios[c].get(run)) for c in conditions) + " |"
              for run in runs), ""]


def _holding_row(ev: Evidence, condition: str, ratios: dict[str, float]) -> str:
    kinds = [holding.kind(r) for r in ratios.values()]
    counts = " / ".join(str(kinds.count(k))
                        for k in (holding.HOLDS, holding.BRUSHES, holding.NO_REACH))
    late = ev.windows.final

    def both(values, digits):        # every outcome here is a count or a sum: never below 0
        return f"{bounded(estimate(values)).text(digits)}; {median(values).text(digits)}"
    return (f"| {condition} | {counts} | {holding.holding_share(list(ratios.values())).text()} "
            f"| {both(list(ratios.values()), 2)} | "
            + " | ".join(both(list(ev.per_run(condition, column, late).values()), digits)
                         for column, digits in (("top_fitness", 0), ("top_successes", 2)))
            + " |")


def _claims(analysis: Analysis) -> list[str]:
    results = analysis.claims["base"]
    return ["## Claims of the paper's Results section vs our measurements\n",
            "Each claim: the paper's words, our rule and its margin, the smallest effect of "
            "interest (written before the data they judge: docs/preregistrations.md), our "
            "measurement, and the criteria that decide its verdict: each a 95% interval over "
            "runs (n = runs; a mean or a paired difference: Student-t; an outcome that splits "
            "into holding and brushing runs, fitness, successful trials and separations: the "
            "median paired difference with its order-statistic interval, the sign test; a "
            "share of runs: Clopper-Pearson) against the region the paper predicts. A "
            "criterion **replicates** when its interval lies inside the region; is **absent** "
            "when it lies within the margin either side of no effect (0 for a difference: the "
            "two one-sided tests at 2.5%); is **reversed** when it lies wholly outside the "
            "region otherwise (for a band, outside the band; for a share of runs, below the "
            "share the paper's count predicts); and is **inconclusive** otherwise. A claim that "
            "needs all its criteria replicates when they all do, is reversed when one is, "
            "absent when one is absent (none reversed); a claim that needs k of its m criteria "
            "(lesion-disorganised: 3 of 4) replicates when k do, is reversed when more than "
            "m - k are reversed, absent when more than m - k are absent or reversed; "
            "inconclusive otherwise. A claim conditional on another (its premise, printed "
            "first among its criteria) is **premise fails** when the premise is absent or "
            "reversed, whatever its own criteria say (printed beside it), and replicates only "
            "when both do. **p** is the p-value of the test the verdict rests "
            "on, raw and Holm-adjusted over the family of claims; the **Holm** verdict keeps "
            "the raw one when the adjusted p is below 0.05 and is inconclusive otherwise. "
            "Chance is the random condition's level, paired by run. Beside each criterion: its "
            "margin and the runs its test needs for 80% power at the margin. *Added* claims "
            "are ones the paper makes in passing. The last columns check each rule against two "
            "nulls: its verdict with random movement in the normal condition's place (a rule "
            "that replicates there cannot tell learning from chance: **flagged**), and how "
            f"often it says 'replicates' on {SHUFFLES} time-shuffled copies of the data (at "
            f"{LEVEL_LIKE:.0%} or more it cannot tell a time course from a level: "
            "**flagged**); '-' where a null cannot test the rule. Machine-readable: claims.csv "
            "beside this report.\n",
            _claims_table(results, nulls=True), *_tally(results)]


def _claims_table(results: list[ClaimResult], nulls: bool = False) -> str:
    head = ("| # | section | paper's claim | our rule | our measurement | criteria: interval "
            "vs region | verdict | p: raw; Holm | Holm verdict |")
    rows = [head + (" random null | shuffled null |" if nulls else ""),
            "|---|---|---|---|---|---|---|---|---|" + ("---|---|" if nulls else "")]
    for i, r in enumerate(results, 1):
        claim = ("*(added)* " if r.claim.added else "") + r.claim.paper
        criteria = "<br>".join(criteria_lines(r.judged)) or "-"
        flags = "".join(f" (flagged: {flag})" for flag in r.flags) + (
            f"<br>at other thresholds: {_readings(r)}" if r.readings else "")
        row = ("| " + " | ".join(map(_escaped, (str(i), r.claim.section, claim, r.claim.rule,
                                                r.ours, criteria)))
               + f" | **{r.verdict}**{flags} | {_p(r.p)}; {_p(r.p_holm)} | {r.adjusted} |")
        if nulls and r.nulls is not None:
            shuffled = "-" if r.nulls.shuffled != r.nulls.shuffled else f"{r.nulls.shuffled:.0%}"
            row += f" {r.nulls.random} | {shuffled} |"
        rows.append(row)
    return "\n".join(rows) + "\n"


def criteria_lines(judged) -> list[str]:
    """A claim's criteria in words, its premise (another claim) first when it has one, with
    the premise's verdict and the claim's own beside it."""
    own = [c.text(four=True) for c in judged.criteria]
    if judged.premise is None:
        return own
    return [f"premise {judged.premise_key}: {judged.premise.verdict}", *(
        c.text(four=True) for c in judged.premise.criteria),
        f"own criteria: {judged.own[0]}", *own]


def _readings(r: ClaimResult) -> str:
    """A claim's raw verdict at each threshold reading, in words."""
    return "; ".join(f"{label}: {verdict}" for label, verdict in r.readings)


def _thresholds(analysis: Analysis) -> list[str]:
    """Every verdict that rests on a threshold the paper does not give, beside the same rule at
    other thresholds (claims.Claim.readings): the registered verdict stands; this says whether
    it would stand elsewhere."""
    results = [(i, r) for i, r in enumerate(analysis.claims["base"], 1) if r.readings]
    if not results:
        return []
    return ["## Thresholds the paper does not give\n",
            "These claims' rules rest on a threshold of ours (a lock at 90/10, a band, a bound "
            "on a ratio). The registered verdict stands; beside it, the raw verdict of the same "
            "rule at other thresholds, so that a verdict that flips with the choice says so.\n",
            "| # | claim | registered rule | verdict (raw; Holm) | at other thresholds (raw) | "
            "flips |", "|---|---|---|---|---|---|",
            *(f"| {i} | {r.claim.key} | {_escaped(r.claim.rule)} | {r.verdict}; {r.adjusted} | "
              f"{_escaped(_readings(r))} | "
              f"{'yes' if any(v != r.verdict for _, v in r.readings) else 'no'} |"
              for i, r in results), ""]


def _p(p: float) -> str:
    return "-" if not np.isfinite(p) else "<0.001" if p < 0.001 else f"{p:.3f}"


def _escaped(text: str) -> str:
    """Text for a Markdown table cell (a '|' would end the cell)."""
    return text.replace("|", "\\|")


def _tally(results: list[ClaimResult]) -> list[str]:
    """The verdicts counted for the paper's claims apart from the added ones, raw and after
    Holm's correction ("premise fails" apart from "reversed": a failure is counted once, where
    it was measured), and how many of each row are flagged by a null."""
    rows = []
    for whose, added in (("the paper's", False), ("added", True)):
        group = [r for r in results if r.claim.added == added]
        flagged = sum(bool(r.flags) for r in group)
        for label, verdict_of in (("raw", lambda r: r.verdict), ("Holm", lambda r: r.adjusted)):
            rows.append(f"| {whose}, {label} | " + " | ".join(
                str(sum(verdict_of(r) == v for r in group)) for v in CLAIM_VERDICTS)
                + f" | {len(group)} | {flagged} |")
    return ["\nTally (flagged: by either null; their verdicts say little about the claim):\n",
            "| claims | " + " | ".join(CLAIM_VERDICTS) + " | all | of them flagged |",
            "|---|" + "---|" * (len(CLAIM_VERDICTS) + 2), *rows, "",
            f"A claim conditional on another is counted as *{PREMISE_FAILS}* when that claim "
            "is absent or reversed, whatever its own criteria say (they are printed beside "
            "it): its failure is that claim's, counted there.\n",
            "Flagged, every one: " + ("; ".join(
                f"{i} {r.claim.key} ({r.verdict}: {', '.join(r.flags)})"
                for i, r in enumerate(results, 1) if r.flags) or "none") + ".\n"]


def _windows(analysis: Analysis) -> list[str]:
    """Which verdicts change when a window moves: one row a moved window, with the claims whose
    verdict changes there; then the claims that depend on any window."""
    if not analysis.moved_windows:
        return []
    base = analysis.claims["base"]
    rows = [(label, [(r, m.verdict) for r, m in zip(base, moved) if m.verdict != r.verdict])
            for label, moved in analysis.moved_windows.items()]
    depend = sorted({base.index(r) for _, changed in rows for r, _ in changed})
    w = analysis.windows
    spans = "; ".join(f"{name} {w.label(w.span(name))}" for name, _ in w.spans)
    return ["## Do the verdicts depend on the windows?\n",
            f"Registered windows: {spans} (docs/analysis.md, 'Windows'). Every claim judged "
            "again with each window moved, one at a time, to half and one and a half times its "
            "length, and the slowdown's also to the windows registered before 2026-12-07:\n",
            "| window moved to | claims whose verdict changes (registered -> moved) |",
            "|---|---|",
            *(f"| {label} | " + ("; ".join(f"{base.index(r) + 1} {r.claim.key}: {r.verdict} -> "
                                           f"{v}" for r, v in changed) or "none") + " |"
              for label, changed in rows),
            f"\n{len(depend)} of {len(base)} claims depend on where a window lies"
            + (": " + ", ".join(f"{i + 1} {base[i].claim.key}" for i in depend) if depend
               else "") + f"; the other {len(base) - len(depend)} keep their verdict under "
            "every move.\n"]


CLAIM_COLUMNS = ["number", "key", "section", "added", "paper", "rule", "ours", "criterion",
                 "estimate", "ci_low", "ci_high", "method", "n", "region", "margin", "verdict",
                 "p_raw", "p_holm", "verdict_holm", "runs_for_80_power", "detectable",
                 "effect_size_dz", "criteria", "null_random_verdict",
                 "null_shuffled_replicates", "flag_random", "flag_shuffled", "window_changes",
                 "premise", "premise_verdict", "own_verdict", "threshold_readings"]


def claim_row(number: int, r: ClaimResult, moved: dict[str, str]) -> dict:
    """One claim as a claims.csv row: the decisive criterion's interval and margin
    (docs/analysis.md, 'claims.csv'), the verdict raw and after Holm's correction with their
    p-values, the runs needed at the margin, every criterion in words, the nulls, both flags
    and the windows that change the verdict (``moved``: window label -> verdict there)."""
    c, nan = r.judged.decisive, float("nan")
    e = c.interval if c else None
    return dict(zip(CLAIM_COLUMNS, (
        number, r.claim.key, r.claim.section, r.claim.added, r.claim.paper, r.claim.rule,
        r.ours, c.what if c else "",
        *((e.mean, e.lo, e.hi, e.method, e.n, c.region, c.margin) if c
          else (nan, nan, nan, "", 0, "", nan)),
        r.verdict, r.p, r.p_holm, r.adjusted, c.runs_needed if c else nan,
        c.detectable if c else nan, c.comparison.effect if c and c.comparison else nan,
        "; ".join(criteria_lines(r.judged)),
        r.nulls.random if r.nulls else "", r.nulls.shuffled if r.nulls else nan,
        r.chance_flagged, r.flagged,
        "; ".join(f"{label}: {v}" for label, v in moved.items() if v != r.verdict),
        r.judged.premise_key, r.judged.premise.verdict if r.judged.premise else "",
        r.judged.own[0], _readings(r))))


def write_claims_csv(path: Path, results: list[ClaimResult],
                     moved: dict[str, list[ClaimResult]] | None = None) -> None:
    moved = moved or {}
    with open(path, "w", newline="", encoding="utf-8") as handle:
        writer = csv.DictWriter(handle, CLAIM_COLUMNS)
        writer.writeheader()
        writer.writerows(claim_row(i, r, {label: m[i - 1].verdict for label, m in moved.items()})
                         for i, r in enumerate(results, 1))


def _performance(analysis: Analysis) -> list[str]:
    return ["## Overall performance (Figure 3)\n",
            f"![Figure 3]({analysis.figures['fig3_performance']})\n"]


def _joint_locking(analysis: Analysis) -> list[str]:
    w = analysis.windows
    lines = ["## 1 Joint locking (Figures 4 and 5)\n",
             f"![Figure 4]({analysis.figures['fig4_shoulder_flexion']})\n",
             f"![Figure 5]({analysis.figures['fig5_elbow_flexion']})\n",
             f"Per run, {w.label(w.final)}, all econets, cycles before first contact "
             f"(locked = flexion <= {LOCK:.0f}% or >= {100 - LOCK:.0f}%; position from the mean "
             "shoulder angle: >= 135 deg extended, <= 45 deg flexed):\n",
             "| run | shoulder flexion % | shoulder angle (deg) | shoulder | first locked at gen | "
             "elbow flexion % | elbow moves in (share of cycles) |",
             "|---|---|---|---|---|---|---|"]
    normal = analysis.groups["base"].get("normal")
    if normal is not None and normal.n_runs:
        lines += [f"| {r['run']} | {fmt(r['shoulder_flexion'], 1)} | "
                  f"{fmt(r['shoulder_angle'], 0)} | {r['position']} | "
                  f"{fmt(r['lock_generation'], 0)} | {fmt(r['elbow_flexion'], 1)} | "
                  f"{fmt(r['elbow_moving'], 2)} |"
                  for r in joint_table(normal, w)]
    return lines + [""]


def _coactivation(analysis: Analysis) -> list[str]:
    return ["## 2 Muscle coactivation (Figures 6 and 7)\n",
            f"![Figure 6]({analysis.figures['fig6_activation_space']})\n",
            f"![Figure 7]({analysis.figures['fig7_coactivation']})\n"]


def _approach(analysis: Analysis) -> list[str]:
    lines = ["## 3 Stereotyped approach movements and the lesion (Figure 8)\n",
             f"![Figure 8]({analysis.figures['fig8_approach']})\n"]
    if "lesion" in analysis.figures:
        lines.append(f"![Lesion]({analysis.figures['lesion']})\n")
    return lines + [_lesion_table(analysis.lesions["base"])]


SURVIVORS = " (successful trials only: survivor-biased)"
LESION_ROWS = [("success_rate", "success rate", 2), ("latency", "latency (cycles)" + SURVIVORS, 1),
               ("latency_every_trial", "latency, every trial (a miss = the trial length)", 1),
               ("approach_prob", "P(approach), pre-contact", 2),
               ("path_efficiency", "path efficiency" + SURVIVORS, 2),
               ("path_efficiency_every_trial", "path efficiency, every trial (gap closed by "
                                               "first contact or the trial's end / path)", 2),
               ("turning", "turning (deg/cycle)", 1),
               ("final_approach_cycles", "final approach (cycles)", 1),
               ("start_spread_body", "reach-start spread, body frame", 1),
               ("start_spread_world", "reach-start spread, workspace", 1),
               ("start_radius", "reach-start distance from shoulder", 1),
               ("reach_elbow_spread", "elbow-angle spread over the last 10 cycles of a reach "
                                      "(posture convergence, deg)", 1),
               ("trial_elbow_spread", "elbow-angle spread at trial start, same trials (deg)", 1)]
LESIONS = ("intact", "lesioned", "vision-lesioned")


def _lesion_table(lesion: list[dict]) -> str:
    if not lesion:
        return "No normal runs: no lesion test.\n"
    rows = [f"Final-generation top-20 econets of {len(lesion)} normal runs, {LESION_TRIALS} fresh "
            "trials each: intact, with the proprioceptive inputs severed (the paper's lesion), "
            "and with the visual inputs severed (a control: does any lesion do the same?); "
            "mean [95% t interval, clipped at 0] over runs:\n",
            "| measure | intact | proprioception severed | vision severed |",
            "|---|---|---|---|"]
    for attr, label, digits in LESION_ROWS:
        cells = [bounded(estimate([getattr(r[kind], attr) for r in lesion])).text(digits)
                 for kind in LESIONS]         # every lesion measure is 0 or more
        rows.append(f"| {label} | " + " | ".join(cells) + " |")
    return "\n".join(rows + _shared_rows(lesion)) + "\n"


def _shared_rows(lesion: list[dict]) -> list[str]:
    """Latency and path efficiency on the trials that both the intact and the proprioception-
    severed nets reach (measures.shared_reaches): the lesion's effect without survivor bias."""
    shared = [shared_reaches(r["intact"], r["lesioned"]) for r in lesion]
    return [f"| {label}, trials both intact and proprioception-severed reach | " + " | ".join(
        bounded(estimate([pair[name][i] for pair in shared])).text(digits) for i in (0, 1))
        + " | - |" for name, label, digits in (("latency", "latency (cycles)", 1),
                                                ("path_efficiency", "path efficiency", 2))]


def _slowdown(analysis: Analysis) -> list[str]:
    return ["## 4 Movement slowdown (Figure 9)\n",
            f"![Figure 9]({analysis.figures['fig9_speed']})\n"]


def _sensitivity(analysis: Analysis) -> list[str]:
    heading = "## Sensitivity to the paper's open assumptions\n"
    if len(analysis.groups) == 1:
        return [heading, "No sensitivity variants in this study (run `econet study "
                "--sensitivity all` to add them).\n"]
    lines = [heading, *_variants(analysis), "", *_verdicts_by_setting(analysis)]
    if "sensitivity" in analysis.figures:
        lines.append(f"![Sensitivity]({analysis.figures['sensitivity']})\n")
    for name in list(analysis.groups)[1:]:
        lines += [f"<details><summary>{name}: measurements</summary>\n",
                  _claims_table(analysis.claims[name]), "\n</details>\n"]
    return lines


def _variants(analysis: Analysis) -> list[str]:
    """What each variant changes and which conditions it ran."""
    lines = ["Each variant re-runs the conditions its setting affects, with the same seeds; "
             "conditions it does not affect are taken from the base study (random movement "
             "ignores network sizes; the three-layer net ignores the four-layer hidden "
             "sizes).\n"]
    for name, changes in analysis.spec.variants.items():
        if name not in analysis.groups:
            continue            # an optimizer variant: see _optimizers
        setting = ", ".join(f"{k}={v}" for k, v in changes.items())
        ran = ", ".join(f"{c} ({d.n_runs} runs)" for c, d in analysis.groups[name].items())
        missing = [p for d in analysis.groups[name].values() for p in d.problems]
        lines.append(f"- **{name}**: {setting}; ran {ran}"
                     + (f"; INCOMPLETE: {'; '.join(missing)}" if missing else ""))
    return lines


def _verdicts_by_setting(analysis: Analysis) -> list[str]:
    """One row a claim: its verdict under the base settings and every variant."""
    names = list(analysis.claims)
    per_claim = list(zip(*(analysis.claims[n] for n in names)))
    keys = [results[0].claim.key for results in per_claim]
    rows = [f"| {key} | " + " | ".join(r.verdict for r in results) + " |"
            for key, results in zip(keys, per_claim)]
    agreed = [len({r.verdict for r in results}) == 1 for results in per_claim]
    same = [k for k, ok in zip(keys, agreed) if ok]
    differ = [k for k, ok in zip(keys, agreed) if not ok]
    return ["| claim | " + " | ".join(names) + " |", "|---|" + "---|" * len(names), *rows, "",
            f"Same verdict under every setting: {', '.join(same) or 'none'}.\n",
            f"Verdict depends on the setting: {', '.join(differ) or 'none'}.\n"]


def _optimizers(analysis: Analysis) -> list[str]:
    """The GA against CMA-ES and the ES, when the study ran them (econet study --optimizers)."""
    return analysis.optimizers.markdown(analysis.figures) if analysis.optimizers else []


def _sweeps(analysis: Analysis) -> list[str]:
    """Each sweep's holding table and its rule's tables, with the path to its own summary;
    then the choice of defaults by the highest rule the sweeps name (rules.py)."""
    if not analysis.sweeps:
        return []
    lines = ["## Sweeps: under which readings of the paper do its findings hold?\n",
             "The decision rules (docs/preregistrations.md, each committed before the sweeps it judges "
             "ran) applied to each sweep; every sweep's full tables and figures are in its own "
             "summary.\n"]
    for sweep in analysis.swept:
        spec, summary = sweep.spec, os.path.join(sweep.published, "summary.md")
        lines += [f"### {spec.name}\n", spec.description + "\n",
                  f"Full tables and figures: [{summary}]({summary})\n"]
        lines += [line.replace("## ", "#### ", 1) for line in
                  holding_markdown(spec, sweep.rows) + rule_of(spec).markdown(sweep)]
    return lines + choose_defaults(analysis.swept)


def _architecture(analysis: Analysis) -> list[str]:
    """The paper's four- against three-layer comparison and its confound, from the sweeps
    whose rule speaks to it (econet analyze --sweep)."""
    return [line for sweep in analysis.swept
            for line in rule_of(sweep.spec).architecture(sweep, analysis.swept)]

"""The page of the pre-registered experiments E1-E4 and the independent check
(docs/preregistrations.md, "Experiments E1-E4 and an independent check"), made from the folders
that hold them, each recognised by what it holds: a sweep folder whose rule is an experiment's
(E1, E2's onset, E3), a transplant folder (E2-T, econet sweep transplant), a screen folder (E2-S,
econet sweep screen), a study folder (E4, its claims.csv) and any folder holding a reference
check's section (REFERENCE_CHECK): a page made from stored results, which never runs a
simulation. The eleven hypotheses are judged
together, Holm over the registered family, and the sentences the registration fixed are chosen
by the adjusted verdicts."""
from __future__ import annotations

import csv
import json
import os
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import ResultsError
from ..provenance import dirty_warning, made_with
from ..science import holding
from ..science.stats import share
from ..science.sweeps.outcomes import published_rows, run_series, tidy_rows
from ..science.sweeps.rules import Swept, rule_of
from ..science.sweeps.spec import load_spec, load_sweep
from ..science.verdicts import (ABSENT, CLAIM_VERDICTS, INCONCLUSIVE, NOT_JUDGED, REPLICATES,
                                REVERSED)
from . import experiments, transplant
from .figures import experiments_figure
from .rules import Experiment
from .screen import TABLE as SCREEN_TABLE
from .screen import Screened, read_screen, screen_criteria, screen_markdown

REFERENCE_CHECK = "reference-check.md"   # the independent check's section, in its sweep folder
ONSET_WINDOW = 20                       # generations: E2's onset is the first such window held


@dataclass
class Folders:
    """What the given folders hold, by kind."""

    sweeps: list[tuple[Path, Swept]] = field(default_factory=list)
    transplants: list[tuple[Path, dict]] = field(default_factory=list)
    screens: list[Screened] = field(default_factory=list)
    studies: list[Path] = field(default_factory=list)
    checks: list[Path] = field(default_factory=list)


def gather(folders: list[Path], published: Path | None = None) -> Folders:
    """Sort the folders by what they hold; ResultsError (one line) for one that holds none. A
    sweep spec (TOML) given instead of a folder stands for its sweep as published in
    ``published`` (outcomes.csv), judged without its run folders."""
    found = Folders()
    for folder in map(Path, folders):
        if folder.suffix == ".toml":
            found.sweeps.append(published_sweep(folder, published))
            continue
        known = False
        if (folder / "sweep.json").exists():
            spec = load_sweep(folder)
            found.sweeps.append((folder, Swept(spec, tidy_rows(spec, folder))))
            known = True
        if (folder / transplant.RECORD).exists():
            record = json.loads((folder / transplant.RECORD).read_text())
            if "transplanted" in transplant.arms_of(record):      # E2's transplant, not E6's
                found.transplants.append((folder, record))
                known = True
        if (folder / SCREEN_TABLE).exists():
            found.screens.append(read_screen(folder))
            known = True
        if (folder / "claims.csv").exists() and (folder / "study.json").exists():
            found.studies.append(folder)
            known = True
        if (folder / REFERENCE_CHECK).exists():
            found.checks.append(folder / REFERENCE_CHECK)
            known = True
        if not known:
            raise ResultsError(f"{folder} holds no experiment: expected a sweep folder, a "
                               f"transplant folder, a screen folder, a study folder or a "
                               f"{REFERENCE_CHECK}")
    return found


def published_sweep(spec_file: Path, published: Path | None) -> tuple[Path, Swept]:
    """A sweep from its spec and the outcomes.csv its report published (in PUBLISHED/name)."""
    spec = load_spec(spec_file)
    table = (published or Path(".")) / spec.name / "outcomes.csv"
    if not table.is_file():
        raise ResultsError(f"{spec_file}: no published outcomes at {table} (give --published "
                           "the folder of the sweeps' summaries)")
    return table.parent, Swept(spec, published_rows(table))


# -- E2's onset: when each run first holds -----------------------------------------------------
def onset_generation(folder: Path) -> int | None:
    """The first generation of the first ONSET_WINDOW-generation window (0-19, 20-39, ...) in
    which the run's top 20 hold: at most holding.LIMIT separations per successful trial over the
    window; None if no window holds."""
    series = run_series(folder)
    separations, successes = series["top_separations"], series["top_successes"]
    for start in range(0, len(successes) - ONSET_WINDOW + 1, ONSET_WINDOW):
        span = slice(start, start + ONSET_WINDOW)
        if holding.kind(holding.per_success(separations[span].sum(), successes[span].sum())) \
                == holding.HOLDS:
            return start
    return None


def onset_markdown(sweep: Swept, folder: Path) -> list[str]:
    """Per cell: how many runs ever hold a window, and the median onset among them (from the
    run folders: a published sweep without them says so)."""
    if not any((r.folder(folder) / "run.json").exists() for r in sweep.spec.runs()):
        return [f"Onset per run: not measurable here (it reads the run folders, which are not "
                f"stored with the published sweep {sweep.spec.name}).", ""]
    lines = [f"| cell | runs | hold late | ever hold a {ONSET_WINDOW}-generation window | "
             "onset (first generation of that window): median, range |", "|---|---|---|---|---|"]
    for cell in sweep.spec.cells:
        runs = [r for r in sweep.spec.runs() if r.cell == cell.name]
        onsets = [onset_generation(r.folder(folder)) for r in runs
                  if (r.folder(folder) / "run.json").exists()]
        held = [o for o in onsets if o is not None]
        late = [r["holding_late"] == holding.HOLDS for r in sweep.rows if r["cell"] == cell.name
                and r["generations_done"]]
        spread = f"{np.median(held):.0f}, {min(held)}-{max(held)}" if held else "n/a"
        lines.append(f"| {cell.name} | {len(onsets)} | {share(late).text(2)} | {len(held)} | "
                     f"{spread} |")
    return lines + [""]


# -- E2's transplant ---------------------------------------------------------------------------
def transplant_markdown(record: dict) -> list[str]:
    """The sources, the check of every transplant, and each arm's holding."""
    runs = record["runs"]
    moved = [r for r in runs if r["source_holds"]]
    lines = [f"Source runs: {len(runs)} ({record['source']}), of which {len(moved)} hold late; "
             f"every transplant scores exactly what its champion did on the champion's own "
             f"trials: {'yes' if all(r['behaves_alike'] for r in moved) else '**no**'} "
             f"({sum(r['behaves_alike'] for r in moved)} of {len(moved)}).\n",
             f"| arm ({'/'.join(map(str, record['into']))}, evolved 200 generations at 2%) | "
             "runs | hold late [95% CI, Clopper-Pearson] |", "|---|---|---|"]
    for arm in transplant.arms_of(record):
        flags = [r[arm] == holding.HOLDS for r in moved]
        lines.append(f"| {arm} | {len(flags)} | {share(flags).text(2)} |")
    return lines + [""]


# -- E4: the claims on fresh runs --------------------------------------------------------------
def read_verdicts(path: Path) -> dict[str, tuple[str, str]]:
    """claims.csv as {claim key: (raw verdict, Holm-adjusted verdict)}."""
    with open(path, newline="", encoding="utf-8") as handle:
        return {row["key"]: (row["verdict"], row["verdict_holm"]) for row in csv.DictReader(handle)}


def claims_markdown(study: Path, against: Path | None) -> list[str]:
    """The tally of E4's claims by their verdicts ("premise fails" apart from "reversed"), raw
    and adjusted, and, against an earlier claims table, where its inconclusive claims went."""
    fresh = read_verdicts(study / "claims.csv")
    lines = ["| verdict | raw | after Holm over the claims |", "|---|---|---|"]
    for verdict in CLAIM_VERDICTS:
        raw = sum(v[0] == verdict for v in fresh.values())
        adjusted = sum(v[1] == verdict for v in fresh.values())
        if raw or adjusted:
            lines.append(f"| {verdict} | {raw} | {adjusted} |")
    lines.append("")
    if against is None:
        return lines
    earlier = read_verdicts(against)
    for index, name in ((0, "raw"), (1, "after Holm")):
        was = [k for k in fresh if k in earlier and earlier[k][index] == INCONCLUSIVE]
        went = Counter(fresh[k][index] for k in was)
        moved = ", ".join(f"{went[v]} {v}" for v in CLAIM_VERDICTS
                          if went[v] and v != INCONCLUSIVE)
        lines.append(f"- {name}: of the {len(was)} claims inconclusive in the earlier table, "
                     f"{len(was) - went[INCONCLUSIVE]} leave inconclusive ({moved or 'none'}); "
                     f"{sum(fresh[k][index] != earlier[k][index] for k in fresh if k in earlier)} "
                     "of all claims change verdict.")
    changed = [k for k in fresh if k in earlier and fresh[k][1] != earlier[k][1]]
    if changed:
        lines.append("- changed after Holm: " + "; ".join(
            f"{k}: {earlier[k][1]} -> {fresh[k][1]}" for k in changed))
    return lines + [""]


# -- the registered sentences --------------------------------------------------------------------
NOT_RUN = "Not among the folders given: not judged here."


E1_S_GAIN = ("E1-S in words: the units have no biases and decode their weights linearly in "
             "the range, so widening the range multiplies every unit's gain; a rising "
             "coefficient says that more saturated units held more often, not that larger "
             "weights avoid saturation.")
E2_AS_BUILT = ("As built, E2 cannot tell discovery from maintenance: the screen counts as "
               "holding a random genome with at most one separation per successful trial, so "
               "one that brushes past once holds; the transplant's added units output 0.5 "
               "whatever touch says, so mutating their zero weights can break holding by "
               "construction. Its verdicts are reported as they fell; neither arm tests what "
               "its name says; a later experiment is to re-test it.")
E1_TERMS = {"E1-N": ("width", "the last hidden layer widens"),
            "E1-W": ("weights", "the weights grow in number")}
E1_UNREGISTERED = {   # each coefficient in words where the pair fits no registered sentence
    REPLICATES: "holding falls as {change}, the fit's other terms held equal",
    ABSENT: "the {term} moves holding by less than the margin",
    REVERSED: "holding rises as {change}, the fit's other terms held equal",
    INCONCLUSIVE: "the {term} coefficient's interval {allows}",
    NOT_JUDGED: "the {term} coefficient could not be measured",
}
E1_MARGIN = 0.5       # log odds per doubling, as registered for every E1 coefficient


def interval_allows(lo: float, hi: float, margin: float = E1_MARGIN) -> str:
    """What a coefficient's interval leaves open, in words: no effect, a fall or a rise beyond
    the margin (and which of the two it rules out)."""
    opened = [word for word, open_ in (("no effect", lo <= 0 <= hi), (f"a fall beyond {margin}",
              lo < -margin), (f"a rise beyond {margin}", hi > margin)) if open_]
    shut = [word for word, shut_ in ((f"a fall of {margin} or more", lo >= -margin),
            (f"a rise of {margin} or more", hi <= margin)) if shut_]
    allows = " and ".join(opened) or "only a small effect"
    return (f"[{lo:.2f}, {hi:.2f}] allows {allows}"
            + (f" and rules out {' and '.join(shut)}" if shut else ""))


def e1_sentence(width: str | None, weights: str | None,
                intervals: dict[str, tuple[float, float]] | None = None) -> str:
    """What the report says of E1-N (width) and E1-W (weights), as registered; for any other
    combination it names the verdicts and, given the coefficients' intervals (log odds per
    doubling), says what each undecided one allows."""
    if width is None or weights is None:
        return NOT_RUN
    if width == REPLICATES and weights == ABSENT:
        return "The width of the last hidden layer, not the number of weights, decides holding."
    if weights == REPLICATES and width == ABSENT:
        return "The number of weights, not the width of the last hidden layer, decides holding."
    if width == weights == REPLICATES:
        return "Both the width of the last hidden layer and the number of weights act on holding."
    if width == weights == ABSENT:
        return ("Neither the width of the last hidden layer nor the number of weights moves "
                "holding by more than the margin.")
    said = [f"Width: {width}; weights: {weights}"]
    if width == REPLICATES:
        said.append("so the registered sentence that the width, not the number of weights, "
                    "decides holding is not reached (it needs the weights absent)")
    verdicts = {"E1-N": width, "E1-W": weights}
    for key, (lo, hi) in (intervals or {}).items():
        term, change = E1_TERMS[key]
        said.append(E1_UNREGISTERED[verdicts[key]].format(
            term=term, change=change, allows=interval_allows(lo, hi)))
    return "; ".join(said) + "."


def e2_sentences(verdicts: dict[str, str]) -> list[str]:
    """What the report says of E2's hypotheses, as registered."""
    screen, kept = verdicts.get("E2-S"), verdicts.get("E2-T")
    said = []
    if kept is None:
        said.append("Without the transplant, discovery and maintenance are not told apart here.")
    elif screen == REPLICATES and kept == REPLICATES:
        said.append("Discovery: random large nets rarely hold once in contact, and a large net "
                    "keeps holding when it is given it.")
    elif kept == REVERSED:
        said.append("Maintenance: a large net given holding loses it under mutation.")
    else:
        said.append(f"Neither discovery nor maintenance is established (E2-S {screen}, "
                    f"E2-T {kept}).")
    longer = [k for k in ("E2-O", "E2-P") if verdicts.get(k) == REPLICATES]
    if longer:
        said.append(f"The large nets' shortfall is one of search ({', '.join(longer)} replicates).")
    return said


E3_SIDE_SENTENCES = {   # E3-H and E3-T in words, by verdict; read beside E3-M's sentence
    "E3-H": {REPLICATES: "The modular net holds more often than the scrambled one.",
             ABSENT: "Modular and scrambled nets hold about equally often (within the margin).",
             REVERSED: "The scrambled net holds more often than the modular one.",
             INCONCLUSIVE: "Whether the modular net holds more often than the scrambled one "
                           "stays inconclusive.",
             NOT_JUDGED: "Whether the modular net holds more often could not be judged (n/a)."},
    "E3-T": {REPLICATES: "The modular net's late fitness is above the three-layer net's of its "
                         "width (4 hidden units).",
             ABSENT: "Against the three-layer net of its width (4 hidden units) the modular "
                     "net's late fitness differs by less than the margin.",
             REVERSED: "The three-layer net of its width (4 hidden units) does better than the "
                       "modular net.",
             INCONCLUSIVE: "Against the three-layer net of its width (4 hidden units) the "
                           "modular net's late fitness stays inconclusive.",
             NOT_JUDGED: "Against the three-layer net of its width the modular net could not "
                         "be judged (n/a)."},
}


def e3_sentences(verdicts: dict[str, str]) -> list[str]:
    """What the report says of E3-M, as registered, then E3-H and E3-T in words."""
    m = verdicts.get("E3-M")
    if m is None:
        return [NOT_RUN]
    said = {REPLICATES: "Splitting the senses helps at equal weights and width: the modular net's "
                        "late fitness is above the scrambled one's.",
            ABSENT: "At equal weights and width, splitting the senses makes no difference to late "
                    "fitness beyond the margin: the paper's modularity claim does not replicate.",
            REVERSED: "At equal weights and width, the scrambled net does better: the claim is "
                      "reversed.",
            INCONCLUSIVE: "Whether splitting the senses helps at equal weights and width stays "
                          "inconclusive.",
            NOT_JUDGED: "Whether splitting the senses helps could not be judged (n/a)."}[m]
    return [said, *(E3_SIDE_SENTENCES[key][verdicts[key]] for key in E3_SIDE_SENTENCES
                    if key in verdicts)]


# -- the page ------------------------------------------------------------------------------------
E1_RULES = ("e1-width", "e1-range")
ONSET_RULES = ("e2-onset", "e2-population")


@dataclass
class Judgement:
    """The family judged once: every hypothesis after Holm, the criteria of each experiment
    sweep (by sweep name)."""

    judged: list[experiments.Hypothesis]
    by_sweep: dict[str, dict]

    @property
    def adjusted(self) -> dict[str, str]:
        return {j.key: j.adjusted for j in self.judged}


def judge(found: Folders) -> Judgement:
    """The screens', the transplants' and the sweeps' criteria, Holm over them all."""
    criteria = {}
    for screened in found.screens:
        criteria.update(screen_criteria(screened))
    for _, record in found.transplants:
        criteria.update(experiments.transplant_kept(transplant.kept_flags(record)))
    by_sweep = {}
    for _, sweep in found.sweeps:
        rule = rule_of(sweep.spec)
        if isinstance(rule, Experiment):
            by_sweep[sweep.spec.name] = rule.criteria(sweep)
            criteria.update(by_sweep[sweep.spec.name])
    return Judgement(experiments.family(criteria), by_sweep)


def header_lines(found: Folders, out: Path, published: Path | None) -> list[str]:
    """The title, the code of the page and of its runs, and each sweep with its summary."""
    runs = [(r["commit"], r["dirty"] is True) for _, s in found.sweeps for r in s.rows
            if r["generations_done"]]
    lines = [*dirty_warning(), "# Experiments E1-E4 and the independent check\n",
             "Pre-registered in [preregistrations.md](../../preregistrations.md#experiments-e1-e4-"
             "and-an-independent-check-pre-registered-written-and-committed-before-any-of-their-"
             "runs) before any of their runs; each is reported as it fell.\n",
             made_with(runs) + "\n"]
    for _, sweep in found.sweeps:
        link = (published / sweep.spec.name / "summary.md") if published else None
        where = (f"[its summary]({os.path.relpath(link, out)})" if link and link.exists()
                 else "its summary: econet sweep report")
        lines.append(f"- sweep **{sweep.spec.name}** ({sweep.spec.rule.get('name', 'no rule')}; "
                     f"{sum(bool(r['generations_done']) for r in sweep.rows)} runs): {where}. "
                     + sweep.registration())
    return lines + [""]


def e1_lines(found: Folders, judgement: Judgement, out: Path) -> list[str]:
    """E1's sentence, each fit's coefficients and the figure."""
    e1 = [s for _, s in found.sweeps if s.spec.rule.get("name") in E1_RULES]
    lines = ["## E1: width, weights or saturation\n",
             e1_sentence(judgement.adjusted.get("E1-N"), judgement.adjusted.get("E1-W"),
                         {j.key: (j.criterion.interval.lo, j.criterion.interval.hi)
                          for j in judgement.judged if j.key in E1_TERMS}) + "\n"]
    for sweep in e1:
        lines += [f"Sweep {sweep.spec.name}, Firth logistic regression of holding "
                  f"({len(experiments.runs_of(sweep.spec, sweep.rows))} runs):\n",
                  *experiments.fit_markdown(sweep.spec, sweep.rows,
                                            judgement.by_sweep[sweep.spec.name])]
    figure = experiments_figure([(s.spec.name, s.spec.rule["name"] == "e1-range",
                                  experiments.runs_of(s.spec, s.rows)) for s in e1],
                                out / "figures")
    if "E1-S" in judgement.adjusted:
        lines.append(E1_S_GAIN + "\n")
    return lines + ([f"![holding per cell]({figure.relative_to(out)})\n"] if figure else [])


def e2_lines(found: Folders, judgement: Judgement) -> list[str]:
    """E2's screen, transplants, onsets and sentences."""
    lines = ["## E2: discovery or maintenance\n"]
    for screened in found.screens:
        lines += [f"The screen (random genomes, no evolution; seeds {screened.seeds}):\n",
                  *screen_markdown(screened), ""]
    for folder, record in found.transplants:
        lines += [f"The transplant ({folder.name}):\n", *transplant_markdown(record)]
    for folder, sweep in found.sweeps:
        if sweep.spec.rule.get("name") in ONSET_RULES:
            lines += [f"Onset, sweep {sweep.spec.name}:\n", *onset_markdown(sweep, folder)]
    return lines + [*e2_sentences(judgement.adjusted), E2_AS_BUILT, ""]


def experiments_page(folders: list[Path], out: Path, against: Path | None = None,
                     published: Path | None = None) -> Path:
    """Write OUT/experiments.md and OUT/figures/; ``published``: where the sweeps' summaries
    are published (linked when there); ``against``: the claims.csv E4's claims are compared
    with."""
    found, out = gather(folders, published), Path(out)
    (out / "figures").mkdir(parents=True, exist_ok=True)
    judgement = judge(found)
    lines = [*header_lines(found, out, published),
             "## The family: eleven hypotheses, Holm over all of them\n",
             *experiments.family_table(judgement.judged), "",
             "Verdicts: replicates / absent (inside the margin) / reversed / inconclusive; "
             "hypotheses whose experiment is not among the folders given are left out.\n",
             *e1_lines(found, judgement, out), *e2_lines(found, judgement),
             "## E3: modularity at equal weights and width\n",
             " ".join(e3_sentences(judgement.adjusted)), ""]
    for study in found.studies:
        lines += [f"## E4: the claims on fresh runs ({study.name})\n",
                  *claims_markdown(study, against)]
    for check in found.checks:
        lines += [check.read_text(encoding="utf-8").strip(), ""]
    page = out / "experiments.md"
    page.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return page

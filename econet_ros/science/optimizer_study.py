"""Are the constraints the task's or the algorithm's? The paper's GA against CMA-ES and an
evolution strategy on the same network, fitness and budget (the study's optimizer variants,
study.OPTIMIZER_VARIANTS; docs/optimizers.md): fitness curves with 95% t intervals over runs,
the four emergent constraints' measures per generation, and the study's claims on each
constraint judged under each optimizer. ROS-free."""
from __future__ import annotations

from dataclasses import dataclass

import matplotlib

matplotlib.use("Agg")     # files only, never a window
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .claims import APPROACH, COACTIVATION, LOCKING, SLOWDOWN, ClaimResult  # noqa: E402
from .evidence import Evidence  # noqa: E402
from .figures import series  # noqa: E402
from .measures import CHANCE  # noqa: E402
from .series import Windows, nanmean  # noqa: E402
from .stats import t_interval  # noqa: E402
from .study import ConditionData, StudySpec, optimizer_only  # noqa: E402
from .verdicts import ABSENT, REPLICATES, REVERSED  # noqa: E402

NAMES = {"ga": "GA (paper)", "cmaes": "CMA-ES", "es": "ES"}
GONE = (ABSENT, REVERSED)      # a constraint is absent where its claim is either
COLORS = {"ga": "tab:blue", "cmaes": "tab:red", "es": "tab:green"}

# Each constraint: its section of the claims table, the claim that says it appears at all, and
# the measure per generation drawn for it (a column, or a function of the group's columns).
CONSTRAINTS = [
    ("shoulder locking", LOCKING, "shoulder-locked"),
    ("muscle coactivation", COACTIVATION, "elbow-coactivated"),
    ("stereotyped approach", APPROACH, "stereotyped-start"),
    ("slowdown", SLOWDOWN, "hand-slowdown"),
]


def _shoulder_dominance(data: ConditionData) -> np.ndarray:
    return np.abs(series(data, "all_shoulder_flexion") - 50.0) / 50.0


def _elbow_coactivation(data: ConditionData) -> np.ndarray:
    return series(data, "top_elbow_recip") - series(data, "top_elbow_coact")


PANELS = [
    ("(a) shoulder locking: |flexion % - 50| / 50, all econets (1: one muscle always wins)",
     _shoulder_dominance, 0.8),
    ("(b) elbow coactivation: deviation from reciprocal - from coactivation (> 0: "
     "coactivated)", _elbow_coactivation, 0.0),
    ("(c) approach: P(approach | fixated), top 20", lambda d: series(d, "top_approach_fix"),
     CHANCE),
    ("(d) slowdown: hand speed while fixated, top 20 (units/cycle)",
     lambda d: series(d, "top_hand_speed_fix"), None),
]


@dataclass
class Comparison:
    """The normal condition's runs under each optimizer (the GA's: the base study's), and the
    study's claims judged on each (three-layer and random from the base study)."""

    arms: dict[str, ConditionData]             # optimizer -> its normal runs
    claims: dict[str, list[ClaimResult]]
    windows: Windows

    @classmethod
    def of(cls, spec: StudySpec, groups: dict, claims: dict) -> "Comparison | None":
        """The comparison a study holds, or None without optimizer variants."""
        names = {"ga": "base"}
        for name, changes in spec.variants.items():
            if optimizer_only(changes) and groups.get(name, {}).get("normal") is not None:
                names[spec.config.replace(**changes).evolution.optimizer] = name
        if len(names) < 2 or groups["base"].get("normal") is None:
            return None
        return cls({opt: groups[name]["normal"] for opt, name in names.items()},
                   {opt: claims[name] for opt, name in names.items()},
                   Windows(spec.config.evolution.generations))

    # -- figures ------------------------------------------------------------------------------
    def drawings(self):
        """(name, figure) pairs for figures.make_figures."""
        yield "optimizers_fitness", self.fitness_figure()
        yield "optimizers_constraints", self.constraints_figure()

    def fitness_figure(self):
        fig, axes = plt.subplots(1, 2, figsize=(11, 4))
        for ax, column, title in ((axes[0], "top_fitness", "top-20 fitness"),
                                  (axes[1], "all_fitness", "whole-population fitness")):
            for opt, data in self.arms.items():
                ci_band(ax, series(data, column), f"{NAMES[opt]} (N={data.n_runs})",
                        COLORS[opt])
            ax.set_title(title)
            ax.set_xlabel("generation")
            ax.legend(fontsize=8)
        fig.suptitle("Fitness under each optimizer: same network, trials and budget (mean over "
                     "runs, band: 95% t interval)")
        return fig

    def constraints_figure(self):
        fig, axes = plt.subplots(2, 2, figsize=(12, 7.6), sharex=True)
        for ax, (title, measure, reference) in zip(axes.ravel(), PANELS):
            for opt, data in self.arms.items():
                ci_band(ax, measure(data), NAMES[opt], COLORS[opt])
            if reference is not None:
                ax.axhline(reference, color="k", lw=0.6, ls=":")
            ax.set_title(title, fontsize=9)
        for ax in axes[1]:
            ax.set_xlabel("generation")
        axes[0, 0].legend(fontsize=8)
        fig.suptitle("The four constraints' measures under each optimizer (mean over runs, band: "
                     "95% t interval; before first contact)")
        return fig

    # -- the report's section -----------------------------------------------------------------
    def markdown(self, figures: dict[str, str]) -> list[str]:
        opts = list(self.arms)
        lines = ["## Are the constraints the task's or the algorithm's?\n",
                 "The paper found four constraints emerging under its genetic algorithm. Here "
                 "the same network, task, fitness and evaluation budget (the same trials each "
                 "generation, runs paired by seed) are evolved by CMA-ES and by an OpenAI-style "
                 "evolution strategy (docs/optimizers.md). A constraint that appears under every "
                 "optimizer does not come from variation by bit flips and selection of the best "
                 "20; it may come from the task (body, senses, fitness) or from the network, "
                 "which all three share, and this comparison cannot tell those apart. One that "
                 "appears under the GA only is the algorithm's.\n",
                 f"![Fitness by optimizer]({figures['optimizers_fitness']})\n",
                 *self._fitness_lines(),
                 f"\n![Constraints by optimizer]({figures['optimizers_constraints']})\n",
                 "Does each constraint appear? Its headline claim's verdict under each "
                 "optimizer (appears = replicates: the claim's intervals lie in the regions the "
                 "paper predicts; absent = absent or reversed; inconclusive or n/a: cannot tell; "
                 "raw verdicts, rules as in the claims table above):\n",
                 "| constraint | claim | " + " | ".join(NAMES[o] for o in opts) + " |",
                 "|---|---|" + "---|" * len(opts)]
        lines += [f"| {label} | {key} | " + " | ".join(self.verdict(o, key) for o in opts) + " |"
                  for label, _, key in CONSTRAINTS]
        return lines + ["", *self._conclusion(), "", *self._claims_by_section(opts)]

    def verdict(self, opt: str, key: str) -> str:
        return next(r.verdict for r in self.claims[opt] if r.claim.key == key)

    def _fitness_lines(self) -> list[str]:
        late = self.windows.final
        evidence = Evidence(self.arms, [], self.windows)
        lines = [f"Top-20 fitness, {self.windows.label(late)}, mean [95% CI] over runs:\n"]
        for opt in self.arms:
            line = f"- {NAMES[opt]}: {evidence.estimate(opt, 'top_fitness', late).text(1)}"
            if opt != "ga":
                diff = evidence.compare((opt, "top_fitness", late), ("ga", "top_fitness", late))
                told = ("ahead of the GA" if diff.diff.lo > 0 else "behind the GA"
                        if diff.diff.hi < 0 else "not told apart from the GA at this n")
                line += f"; {NAMES[opt]} - GA, paired by run: {diff.text(1)}: {told}"
            lines.append(line)
        return lines

    def _conclusion(self) -> list[str]:
        """Where each constraint appears (its claim replicates) and where it is absent (absent
        or reversed): not the algorithm's when it appears under every optimizer, the
        algorithm's when it appears under the GA and is absent under every other; otherwise it
        cannot be told."""
        task, algorithm, absent, untold = [], [], [], []
        for label, _, key in CONSTRAINTS:
            verdicts = [self.verdict(opt, key) for opt in self.arms]      # the arms' order
            others = [v for opt, v in zip(self.arms, verdicts) if opt != "ga"]
            if all(v == REPLICATES for v in verdicts):
                task.append(label)
            elif self.verdict("ga", key) == REPLICATES and all(v in GONE for v in others):
                algorithm.append(label)
            elif all(v in GONE for v in verdicts):
                absent.append(label)
            else:
                untold.append(f"{label} (" + ", ".join(
                    f"{NAMES[o]} {v}" for o, v in zip(self.arms, verdicts)) + ")")
        return [f"- Under every optimizer (not the GA's; the task's or the shared network's): "
                f"{', '.join(task) or 'none'}.",
                f"- Under the GA only, absent under the others (the algorithm's): "
                f"{', '.join(algorithm) or 'none'}.",
                f"- Absent under every optimizer: {', '.join(absent) or 'none'}.",
                f"- Cannot be told from these runs: {', '.join(untold) or 'none'}."]

    def _claims_by_section(self, opts: list[str]) -> list[str]:
        sections = {section for _, section, _ in CONSTRAINTS}
        lines = ["Every claim on the four constraints under each optimizer, raw verdicts (a "
                 "claim that compares with the three-layer or random condition reads the base "
                 "study's runs of it, the same under every optimizer):\n",
                 "| claim | " + " | ".join(NAMES[o] for o in opts) + " |",
                 "|---|" + "---|" * len(opts)]
        for i, result in enumerate(self.claims["ga"]):
            if result.claim.section in sections:
                lines.append(f"| {result.claim.key} | "
                             + " | ".join(self.claims[o][i].verdict for o in opts) + " |")
        for opt in opts[1:]:
            lines += [f"\n<details><summary>{NAMES[opt]}: measurements</summary>\n",
                      *(f"- {r.claim.key}: {r.ours} (**{r.verdict}**)" for r in self.claims[opt]
                        if r.claim.section in sections), "\n</details>"]
        return lines + [""]


def ci_band(ax, values: np.ndarray, label: str, color: str) -> None:
    """Mean over runs per generation, with its 95% t interval as a band."""
    x = np.arange(values.shape[1])
    bounds = np.array([t_interval(column) for column in values.T])
    ax.plot(x, nanmean(values, axis=0), color=color, lw=1.4, label=label)
    ax.fill_between(x, bounds[:, 0], bounds[:, 1], color=color, alpha=0.2, lw=0)

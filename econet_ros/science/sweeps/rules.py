"""The decision rules a sweep can name, by name (RULES): `rule = "NAME"` in its TOML, or a [rule]
table with `name = "NAME"` and the cells (and companion sweep) the rule needs, and, for a rule
committed before its sweep ran, `registered = "<commit>"`: the commit that registered it. A
rule says what its sweep's summary shows (markdown, figures), what it makes of the defaults,
and what it adds to the study report's architecture section; the report asks the rule and
never the sweep's name. The rules' arithmetic lives in the studies wing (econet_ros/studies):
regime.py (the rule of "Finding the paper's regime"), confirm.py (the pre-registered rule:
H1-H3 and the exploratory readings) and experiments.py (the experiments E1-E3)."""
from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from ...errors import ConfigError
from ...provenance import registration
from ...studies import confirm, experiments, regime
from .figures import LOAD_MAP, load_map_figure
from .plan import SweepSpec

REGISTERED = "registered"    # a [rule] table's option: the commit that pre-registered the rule
PREREGISTERED = "## The pre-registered rule (docs/preregistrations.md, \"The confirmatory study\")\n"
EXPERIMENTS = ("## The pre-registered rule (docs/preregistrations.md, \"Experiments E1-E4 and an "
               "independent check\")\n")


@dataclass(frozen=True)
class Swept:
    """A sweep as a rule reads it: its spec, its tidy rows (outcomes.py) and, in a study report,
    the folder its summary is published in, relative to the report."""

    spec: SweepSpec
    rows: list[dict]
    published: str = ""

    @property
    def options(self) -> dict:
        return self.spec.rule

    def registration(self) -> str:
        """Whether the commit that registered the sweep's rule is an ancestor of the commits of
        all its runs, as a sentence ("" for a rule without a registration)."""
        if REGISTERED not in self.options:
            return ""
        return registration(self.options[REGISTERED],
                            [row["commit"] for row in self.rows if row["generations_done"]])


class Rule:
    """No rule: the general tables only. A rule names the options its [rule] table takes: CELLS
    name one cell of the sweep each, PAIRS two; SWEEPS, which may be left out, another sweep of
    the same study report."""

    name = ""
    cells: tuple[str, ...] = ()
    pairs: tuple[str, ...] = ()
    sweeps: tuple[str, ...] = ()

    def check(self, options: dict, cell_names: set[str]) -> None:
        """ConfigError (one line) unless the options are this rule's, each naming what it
        should: cells the sweep has, or another sweep."""
        needed, allowed = {*self.cells, *self.pairs}, {*self.cells, *self.pairs, *self.sweeps}
        given = set(options) - {"name", REGISTERED}
        if not needed <= given <= allowed:
            raise ConfigError(f"rule '{self.name}' takes the option(s) "
                              f"{', '.join(sorted(allowed)) or 'none'} in a [rule] table, got "
                              f"{', '.join(sorted(given)) or 'none'}")
        for key in given & set(self.sweeps):
            if not isinstance(options[key], str):
                raise ConfigError(f"rule option {key} must name a sweep, got {options[key]!r}")
        for key in (*self.cells, *self.pairs):
            value, count = options[key], 2 if key in self.pairs else 1
            named = value if isinstance(value, list) else [value]
            if len(named) != count or not all(isinstance(c, str) and c in cell_names
                                              for c in named):
                what = "a cell" if count == 1 else "two cells"
                raise ConfigError(f"rule option {key} must name {what} of the spec "
                                  f"({', '.join(sorted(cell_names))}), got {value!r}")

    def markdown(self, sweep: Swept) -> list[str]:
        """The rule's section of the sweep's summary (and, a level down, of the report)."""
        return []

    def figures(self, sweep: Swept, folder: Path) -> list[Path]:
        return []

    def defaults(self, sweeps: list[Swept]) -> list[str]:
        """The choice of defaults by this rule over the report's sweeps that name it ([]:
        nothing to say)."""
        return []

    def architecture(self, sweep: Swept, others: list[Swept]) -> list[str]:
        """The study report's section on the architecture comparison ([]: none)."""
        return []


class Regime(Rule):
    """The decision rule of "Finding the paper's regime": F1-F4 and B1-B4 of every setting (an
    F - T comparison with an F - R one of the same four-layer cell)."""

    name = "regime"

    def markdown(self, sweep: Swept) -> list[str]:
        return regime.regime_markdown(sweep.spec, sweep.rows)

    def defaults(self, sweeps: list[Swept]) -> list[str]:
        judged = [v for s in sweeps for v in regime.verdicts(s.spec, s.rows)]
        return regime.defaults_markdown(judged) if judged else []


class Confirmatory(Rule):
    """H1 and H2 on the networks FOUR (F), PAPER (T8) and MATCHED (T4), with the regime rule's
    table beside them; H1 decides the defaults; the study report's architecture section, with
    H3 from the sweep MAP when the report is given it too."""

    name = "confirmatory"
    cells = ("four", "paper", "matched")
    sweeps = ("map",)

    def networks(self, sweep: Swept) -> confirm.Networks:
        return confirm.Networks.named(*(sweep.options[key] for key in self.cells))

    def markdown(self, sweep: Swept) -> list[str]:
        return [PREREGISTERED, *confirm.confirmatory(sweep.spec, sweep.rows, self.networks(sweep)),
                *regime.regime_markdown(sweep.spec, sweep.rows)]

    def defaults(self, sweeps: list[Swept]) -> list[str]:
        if not sweeps:
            return []
        s = sweeps[0]
        verdict = confirm.decide(s.spec, s.rows, self.networks(s))
        return ["### Choosing the defaults\n", confirm.defaults_sentence(verdict) + "\n"]

    def architecture(self, sweep: Swept, others: list[Swept]) -> list[str]:
        found = next((s for s in others if s.spec.name == sweep.options.get("map")), None)
        mapped, figure = None, ""
        if found is not None:
            mapped = (found.spec, found.rows, LoadMap.equal_loads(found))
            figure = os.path.join(found.published, "figures", LOAD_MAP)
        return confirm.architecture(sweep.spec, sweep.rows, self.networks(sweep), mapped, figure)


class LoadMap(Rule):
    """H3 on the map of mutational load: cells named SIZE-L<load> or SIZE-p<rate in %>; H3d's
    pairs of equal load EQUAL_LOW and EQUAL_HIGH; the map figure."""

    name = "load-map"
    pairs = ("equal_low", "equal_high")

    @staticmethod
    def equal_loads(sweep: Swept) -> confirm.EqualLoads:
        return confirm.EqualLoads(tuple(sweep.options["equal_low"]),
                                  tuple(sweep.options["equal_high"]))

    def markdown(self, sweep: Swept) -> list[str]:
        return [PREREGISTERED, *confirm.load_map(sweep.spec, sweep.rows, self.equal_loads(sweep))]

    def figures(self, sweep: Swept, folder: Path) -> list[Path]:
        runs = confirm.map_runs(sweep.spec, sweep.rows)
        return [load_map_figure(confirm.map_cells(runs), folder)]


class Readings(Rule):
    """The exploratory readings: each [[compare]] entry, a reading's cell against its size's
    default-reading cell (no verdicts)."""

    name = "readings"

    def markdown(self, sweep: Swept) -> list[str]:
        return [PREREGISTERED, *confirm.readings(sweep.spec, sweep.rows)]


class Experiment(Rule):
    """A rule of the pre-registered experiments: its hypotheses as criteria (experiments.py),
    shown with their raw four-way verdicts, Holm-adjusted within the sweep; the registered
    correction over the whole family is family_markdown, which a later report is to call."""

    def criteria(self, sweep: Swept) -> dict:
        raise NotImplementedError

    def markdown(self, sweep: Swept) -> list[str]:
        return [EXPERIMENTS, *experiments.family_table(experiments.family(self.criteria(sweep))),
                "\nHolm-adjusted here over this sweep's hypotheses only; the registered family "
                "is all eleven of E1-E3, judged together once every experiment has run.\n"]


class E1Width(Experiment):
    """E1-N, E1-W, E1-A: a model of holding on log2 weights, log2 width and three layers."""

    name = "e1-width"

    def criteria(self, sweep: Swept) -> dict:
        return experiments.e1_width(sweep.spec, sweep.rows)


class E1Range(Experiment):
    """E1-S: holding against the weight range (saturation)."""

    name = "e1-range"

    def criteria(self, sweep: Swept) -> dict:
        return experiments.e1_range(sweep.spec, sweep.rows)


class E2Onset(Experiment):
    """E2-O: the share of the LARGE cell's runs that hold late in longer runs."""

    name = "e2-onset"
    key = "E2-O"
    cells = ("large",)

    def criteria(self, sweep: Swept) -> dict:
        return experiments.onset(sweep.spec, sweep.rows, sweep.options["large"], self.key)


class E2Population(E2Onset):
    """E2-P: the same in a larger population."""

    name = "e2-population"
    key = "E2-P"


class E3Modularity(Experiment):
    """E3-M, E3-H, E3-T: MODULAR 2/2/4 against SCRAMBLED 2/2/4 and THREE-layer 4."""

    name = "e3-modularity"
    cells = ("modular", "scrambled", "three")

    def criteria(self, sweep: Swept) -> dict:
        o = sweep.options
        return experiments.e3(sweep.spec, sweep.rows, experiments.Modularity(
            (o["modular"], "normal"), (o["scrambled"], "normal"), (o["three"], "three-layer")))


def family_markdown(sweeps: list[Swept], extra: dict | None = None) -> list[str]:
    """The registered family of E1-E3 over the sweeps that name an experiment's rule, with
    EXTRA criteria judged outside sweeps (E2's screen and transplant), Holm over all of them."""
    criteria = dict(extra or {})
    for sweep in sweeps:
        rule = rule_of(sweep.spec)
        if isinstance(rule, Experiment):
            criteria.update(rule.criteria(sweep))
    return experiments.family_table(experiments.family(criteria)) if criteria else []


NO_RULE = Rule()
# by precedence: the first rule with something to say chooses the defaults (the pre-registered
# confirmatory rule supersedes the earlier regime rule)
RULES: dict[str, Rule] = {rule.name: rule for rule in (
    Confirmatory(), Regime(), LoadMap(), Readings(), E1Width(), E1Range(), E2Onset(),
    E2Population(), E3Modularity())}


def rule_of(spec: SweepSpec) -> Rule:
    """The rule a sweep names; NO_RULE for a sweep without one."""
    return RULES[spec.rule["name"]] if spec.rule else NO_RULE


def choose_defaults(sweeps: list[Swept]) -> list[str]:
    """The choice of defaults by the highest rule that any of the sweeps names."""
    for rule in RULES.values():
        lines = rule.defaults([s for s in sweeps if rule_of(s.spec) is rule])
        if lines:
            return lines
    return []

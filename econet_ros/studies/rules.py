"""This project's decision rules, registered by name in setup.cfg (econet_ros.rules) and named by
the sweeps' TOML (examples/sweeps): the regime rule (regime.py), the confirmatory study's
(confirm.py: H1-H3 and the exploratory readings) and the experiments E1-E3's and E7's
(experiments.py)."""
from __future__ import annotations

import os
from pathlib import Path

from ..science.sweeps.rules import Rule, Swept
from . import confirm, experiments, regime
from .figures import LOAD_MAP, load_map_figure

PREREGISTERED = "## The pre-registered rule (docs/preregistrations.md, \"The confirmatory study\")\n"
EXPERIMENTS = ("## The pre-registered rule (docs/preregistrations.md, \"Experiments E1-E4 and an "
               "independent check\")\n")
LATER = "## The pre-registered rule (docs/preregistrations.md, \"E6-E9 and the E5-E9 family\")\n"


class Regime(Rule):
    """The decision rule of "Finding the paper's regime": F1-F4 and B1-B4 of every setting (an
    F - T comparison with an F - R one of the same four-layer cell)."""

    name = "regime"
    precedence = 1

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
    precedence = 2
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
    correction over the whole family is the experiments' page's (family.py)."""

    heading, registered = EXPERIMENTS, experiments.FAMILY
    whole = "all eleven of E1-E3"

    def criteria(self, sweep: Swept) -> dict:
        raise NotImplementedError

    def readings(self, sweep: Swept) -> list[str]:
        return []

    def markdown(self, sweep: Swept) -> list[str]:
        judged = experiments.family(self.criteria(sweep), self.registered)
        return [self.heading, *experiments.family_table(judged),
                f"\nHolm-adjusted here over this sweep's hypotheses only; the registered family "
                f"is {self.whole}, judged together once every experiment has run.\n",
                *self.readings(sweep)]


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


class E7Dose(Experiment):
    """E7-D and E7-W: holding on width over the DOSE cells (first layers fixed), on weights over
    the CONTROL cells (width fixed)."""

    name = "e7-dose"
    groups = ("dose", "control")
    heading, registered = LATER, experiments.FAMILY_E5_E9
    whole = "the 21 of E5-E9"

    def criteria(self, sweep: Swept) -> dict:
        return experiments.e7_dose(sweep.spec, sweep.rows, sweep.options["dose"],
                                   sweep.options["control"])

    def readings(self, sweep: Swept) -> list[str]:
        return experiments.e7_readings(sweep.spec, sweep.rows, sweep.options["dose"])


class E2Screen(Rule):
    """E2-S's screen spec (econet sweep screen, screen.py): LARGE and SMALL name the cells whose
    random genomes' holding shares it sets against each other."""

    name = "e2-screen"
    cells = ("large", "small")


class E6Screen(E2Screen):
    """E6-S's screen spec: the same cells, judged by E6's holding criterion (screen.py)."""

    name = "e6-screen"

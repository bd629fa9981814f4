"""The decision rules a sweep can name, plug-ins by name (plugins.py, entry-point group
econet_ros.rules, or module:Class): `rule = "NAME"` in its TOML, or a [rule]
table with `name = "NAME"` and the cells (and companion sweep) the rule needs, and, for a rule
committed before its sweep ran, `registered = "<commit>"`: the commit that registered it. A
rule says what its sweep's summary shows (markdown, figures), what it makes of the defaults,
and what it adds to the study report's architecture section; the report asks the rule and
never the sweep's name. This project's own rules live in its studies wing
(econet_ros/studies/rules.py)."""
from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from pathlib import Path

from ...errors import ConfigError
from ...plugins import Kind, find, registered_in
from ...provenance import registration
from .plan import SweepSpec

REGISTERED = "registered"    # a [rule] table's option: the commit that pre-registered the rule


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
    name one cell of the sweep each, PAIRS two, GROUPS two or more; SWEEPS, which may be left
    out, another sweep of the same study report."""

    name = ""
    precedence = 0     # of the rules a study report's sweeps name, the highest chooses defaults
    cells: tuple[str, ...] = ()
    pairs: tuple[str, ...] = ()
    groups: tuple[str, ...] = ()
    sweeps: tuple[str, ...] = ()

    def check(self, options: dict, cell_names: set[str]) -> None:
        """ConfigError (one line) unless the options are this rule's, each naming what it
        should: cells the sweep has, or another sweep."""
        needed = {*self.cells, *self.pairs, *self.groups}
        allowed = needed | set(self.sweeps)
        given = set(options) - {"name", REGISTERED}
        if not needed <= given <= allowed:
            raise ConfigError(f"rule '{self.name}' takes the option(s) "
                              f"{', '.join(sorted(allowed)) or 'none'} in a [rule] table, got "
                              f"{', '.join(sorted(given)) or 'none'}")
        for key in given & set(self.sweeps):
            if not isinstance(options[key], str):
                raise ConfigError(f"rule option {key} must name a sweep, got {options[key]!r}")
        for key in (*self.cells, *self.pairs, *self.groups):
            value = options[key]
            named = value if isinstance(value, list) else [value]
            count = 2 if key in self.pairs else 1
            fits = len(named) >= 2 if key in self.groups else len(named) == count
            if not fits or not all(isinstance(c, str) and c in cell_names for c in named):
                what = ("two or more cells" if key in self.groups
                        else "a cell" if count == 1 else "two cells")
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


NO_RULE = Rule()
RULES = Kind("rule", "econet_ros.rules", Rule)


def known_rules() -> list[str]:
    """The registered rule names."""
    return sorted(registered_in(RULES))


@cache
def named_rule(name: str) -> Rule:
    """The rule a name stands for: a registered name or module:Class (PluginError if none)."""
    return find(RULES, name)()


def rule_of(spec: SweepSpec) -> Rule:
    """The rule a sweep names; NO_RULE for a sweep without one."""
    return named_rule(spec.rule["name"]) if spec.rule else NO_RULE


def choose_defaults(sweeps: list[Swept]) -> list[str]:
    """The choice of defaults by the rule of highest precedence among those the sweeps name
    that has something to say (a later rule may supersede an earlier one)."""
    named = sorted(dict.fromkeys(rule_of(s.spec) for s in sweeps), key=lambda r: -r.precedence)
    for rule in named:
        lines = rule.defaults([s for s in sweeps if rule_of(s.spec) is rule])
        if lines:
            return lines
    return []

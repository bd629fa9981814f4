"""A sweep names its decision rule in its TOML: the rule is checked when the spec is read, kept in
the sweep folder, and the reports ask the rule, never the sweep's name; a rule is a plug-in, by
a registered name or module:Class. (How our studies' rules choose defaults and check their
registration: tests/studies/test_confirm.py.)"""
import json
from pathlib import Path

import pytest

from econet_ros.errors import ConfigError, PluginError, ResultsError
from econet_ros.science.sweeps.plan import SweepSpec
from econet_ros.science.sweeps.rules import (NO_RULE, Rule, Swept, choose_defaults, known_rules,
                                             named_rule, rule_of)
from econet_ros.science.sweeps.spec import load_spec, load_sweep, prepare_folder

SPECS = Path(__file__).resolve().parents[3] / "examples" / "sweeps"
# the commit that wrote the confirmatory study's and the map's pre-registration into the docs
REGISTRATION = "8b795cf729e77c19bbb05e21bbfdc270fb52c859"
CELLS = """
[cells.F]
conditions = ["normal"]
[cells.T]
conditions = ["three-layer"]
"""


def spec_from(tmp_path: Path, text: str) -> SweepSpec:
    path = tmp_path / "spec.toml"
    path.write_text(text, encoding="utf-8")
    return load_spec(path)


def test_a_spec_without_a_rule_gets_no_rule_section(tmp_path):
    spec = spec_from(tmp_path, 'name = "confirm"\n' + CELLS)      # the name decides nothing
    assert spec.rule == {} and rule_of(spec) is NO_RULE
    assert NO_RULE.markdown(Swept(spec, [])) == [] and choose_defaults([Swept(spec, [])]) == []


def test_an_unknown_rule_is_refused_in_one_line_naming_the_known_ones(tmp_path):
    with pytest.raises(ConfigError) as error:
        spec_from(tmp_path, 'rule = "regim"\n' + CELLS)
    message = str(error.value)
    assert "\n" not in message and all(name in message for name in known_rules())


@pytest.mark.parametrize("table, wrong", [
    ('name = "confirmatory"\nfour = "F"\npaper = "T"\nmap = "m"', "matched"),     # missing
    ('name = "confirmatory"\nfour = "F"\npaper = "T"\nmatched = "X"\nmap = "m"', "X"),
    ('name = "load-map"\nequal_low = ["F"]\nequal_high = ["F", "T"]', "equal_low"),
    ('name = "regime"\nfour = "F"', "four"),                  # the regime rule takes none
    ('name = "regime"\nregistered = "HEAD"', "registered must be a git commit"),
    ('name = "regime"\nregistered = 8', "registered must be a git commit"),
])
def test_a_rule_table_must_name_the_cells_its_rule_needs(tmp_path, table, wrong):
    with pytest.raises(ConfigError, match=wrong):
        spec_from(tmp_path, CELLS + "[rule]\n" + table + "\n")


class OwnRule(Rule):
    """A user's own rule, named by module:Class in a spec."""

    cells = ("mine",)

    def markdown(self, sweep: Swept) -> list[str]:
        return [f"## My rule on {sweep.options['mine']}"]


def test_a_rule_of_ones_own_is_named_by_module_and_class(tmp_path):
    spec = spec_from(tmp_path, CELLS + '[rule]\nname = "test_rules:OwnRule"\nmine = "F"\n')
    assert isinstance(rule_of(spec), OwnRule)
    assert rule_of(spec).markdown(Swept(spec, [])) == ["## My rule on F"]
    with pytest.raises(ConfigError, match="mine"):
        spec_from(tmp_path, CELLS + '[rule]\nname = "test_rules:OwnRule"\n')


@pytest.mark.parametrize("name, fragment", [
    ("test_rules:Missing", "has no 'Missing'"),
    ("os:getcwd", "is not a subclass of econet_ros.science.sweeps.rules.Rule"),
])
def test_a_rule_name_that_resolves_to_no_rule_is_one_line(tmp_path, name, fragment):
    with pytest.raises(PluginError, match=fragment) as error:
        spec_from(tmp_path, f'rule = "{name}"\n' + CELLS)
    assert "\n" not in str(error.value)


def test_a_companion_sweep_may_be_left_out(tmp_path):
    spec = spec_from(tmp_path, CELLS + '[rule]\nname = "confirmatory"\nfour = "F"\n'
                     'paper = "T"\nmatched = "T"\n')
    assert rule_of(spec) is named_rule("confirmatory")


def test_the_rule_is_kept_in_the_sweep_folder(tmp_path):
    spec = load_spec(SPECS / "confirm.toml")
    prepare_folder(spec, tmp_path)
    assert load_sweep(tmp_path).rule == spec.rule == {
        "name": "confirmatory", "four": "four-2-2-4", "paper": "three-8", "matched": "three-4",
        "map": "load-map", "registered": REGISTRATION}


def test_a_folder_made_before_rules_is_refused_then_given_the_rule_but_not_other_runs(tmp_path):
    spec = load_spec(SPECS / "readings.toml")
    stored = spec.to_dict()
    del stored["rule"]                       # as written before sweeps named rules
    stored["description"] = "an older wording"
    (tmp_path / "sweep.json").write_text(json.dumps(stored), encoding="utf-8")
    with pytest.raises(ResultsError, match="before sweeps named their decision rule"):
        load_sweep(tmp_path)                 # its report would lack the rule's sections
    prepare_folder(spec, tmp_path)           # what `econet sweep run SPEC --out DIR` does first
    assert load_sweep(tmp_path).rule == {"name": "readings"}
    other = load_spec(SPECS / "readings.toml")
    other.seeds = (1, 2)
    with pytest.raises(ResultsError, match="different sweep"):
        prepare_folder(other, tmp_path)


@pytest.mark.parametrize("path", sorted(SPECS.glob("*.toml")), ids=lambda p: p.stem)
def test_every_example_spec_reads_with_its_rule(path):
    spec = load_spec(path)
    assert rule_of(spec) is (named_rule(spec.rule["name"]) if spec.rule else NO_RULE)
    assert "issue" not in path.read_text(encoding="utf-8").lower()

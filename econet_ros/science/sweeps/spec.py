"""Sweeps over the paper's open choices: which readings of the paper a finding holds under.

A sweep specification is a TOML file (read with the standard library's tomllib):

    name = "smoke"
    generations = 5
    seeds = [1, 2]                       # or {first = 1, count = 10}
    conditions = ["normal", "three-layer"]
    behaviour = true                     # also record behaviour.csv (Figures 4-9 measures)
    rule = "NAME"                        # the decision rule its report applies (rules.py)

    [settings]                           # changes every cell makes (dotted config keys)
    "evolution.population" = 20

    [cells.small]                        # named cells: each a set of config changes ...
    set = {"network.visual_hidden" = 2}
    conditions = ["normal"]              # ... and, if not the spec's, its own conditions

    [factors]                            # crossed with each other (and with the named cells)
    "evolution.mutation_mode" = ["per-bit", "weights"]

    [[compare]]                          # paired comparisons for the report
    a = {condition = "normal"}           # within every cell: normal minus three-layer
    b = {condition = "three-layer"}

A rule that needs named cells (or a companion sweep) takes them in a [rule] table instead of
the rule = "NAME" line, e.g. name = "NAME" and large = "CELL" (each rule's options: its
class); a pre-registered rule names the commit that registered it, registered = "<commit>",
and the report checks that it precedes every run's commit. Without a rule the report shows the
general tables only (cells, outcomes, comparisons, holding) and the sweep adds nothing to a
study report's choice of defaults.

Every cell runs every seed, and a run is (cell, condition, seed) evolved as run 1 of that seed,
so the same seed gives the same trial starts in every cell and condition: runs pair by seed.
Results: OUT/sweep.json (the specification as read) and OUT/<cell>/<condition>/seed-NNN/ (a run
folder, plus behaviour.csv). docs/sweeps.md explains the format in full.
"""
from __future__ import annotations

import itertools
import json
import tomllib
from pathlib import Path
from typing import Any

from ...config import CONDITIONS, SETTINGS, Config
from ...errors import ConfigError, ResultsError
from ...provenance import COMMIT
from ...run_folders import RunData
from .plan import FORMAT, Cell, Run, SweepSpec
from .rules import REGISTERED, known_rules, named_rule

RESERVED = ("evolution.condition", "evolution.generations")
TOP_KEYS = {"name", "description", "generations", "seeds", "conditions", "behaviour",
            "settings", "cells", "factors", "compare", "rule"}
REPORTING = ("description", "rule")     # what a report says, not what runs: a re-run may change it


# -- reading a specification -------------------------------------------------------------------
def load_spec(path: Path) -> SweepSpec:
    """A checked specification; ConfigError (one line) on anything that cannot work, before
    any run starts."""
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except OSError as error:
        raise ConfigError(f"cannot read sweep spec {path}: {error.strerror}") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as error:
        raise ConfigError(f"sweep spec {path} is not valid TOML: {error}") from None
    try:
        spec = _spec_from_toml(data, default_name=path.stem)
    except ConfigError as error:
        raise ConfigError(f"sweep spec {path}: {error}") from None
    for cell in spec.cells:            # every cell and condition must make a valid Config
        for condition in cell.conditions:
            try:
                spec.config(cell, condition)
            except ConfigError as error:
                raise ConfigError(f"sweep spec {path}: cell '{cell.name}', {condition}: "
                                  f"{error}") from None
    return spec


def _spec_from_toml(data: dict, default_name: str) -> SweepSpec:
    unknown = set(data) - TOP_KEYS
    if unknown:
        raise ConfigError(f"unknown key(s) {', '.join(sorted(unknown))} (allowed: "
                          f"{', '.join(sorted(TOP_KEYS))})")
    conditions = _conditions(data.get("conditions", ["normal"]), "conditions")
    settings = _changes(data.get("settings", {}), "settings")
    cells = _cells(data.get("cells", {}), _factors(data.get("factors", {})), conditions)
    spec = SweepSpec(_text(data.get("name", default_name), "name"), _generations(data),
                     _seeds(data.get("seeds", [1])), cells, settings,
                     _flag(data.get("behaviour", True), "behaviour"),
                     _comparisons(data.get("compare", [])),
                     _text(data.get("description", ""), "description"),
                     _rule(data.get("rule")))
    _check_comparisons(spec)
    if spec.rule:
        named_rule(spec.rule["name"]).check(spec.rule, {c.name for c in spec.cells})
    return spec


def _text(value: Any, what: str) -> str:
    if not isinstance(value, str):
        raise ConfigError(f"{what} must be a string, got {value!r}")
    return value


def _flag(value: Any, what: str) -> bool:
    if not isinstance(value, bool):
        raise ConfigError(f"{what} must be true or false, got {value!r}")
    return value


def _rule(value: Any) -> dict:
    """rule = "NAME", or a [rule] table with name = "NAME" and the rule's options."""
    if value is None:
        return {}
    choice = {"name": value} if isinstance(value, str) else value
    if not isinstance(choice, dict) or not isinstance(choice.get("name"), str) \
            or not (choice["name"] in known_rules() or ":" in choice["name"]):
        raise ConfigError(f"rule must be one of {', '.join(known_rules())} or module:Class (or a "
                          f"[rule] table with name = one of them), got {value!r}")
    registered = choice.get(REGISTERED)
    if registered is not None and not (isinstance(registered, str)
                                       and COMMIT.fullmatch(registered)):
        raise ConfigError(f"rule option {REGISTERED} must be a git commit (7 to 40 lowercase hex "
                          f"digits), got {registered!r}")
    return dict(choice)


def _generations(data: dict) -> int:
    value = data.get("generations", Config().evolution.generations)
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise ConfigError(f"generations must be a whole number of at least 1, got {value!r}")
    return value


def _seeds(value: Any) -> tuple[int, ...]:
    """A list of whole numbers >= 0, or {first = F, count = N}."""
    if isinstance(value, dict) and set(value) == {"first", "count"}:
        first, count = value["first"], value["count"]
        if all(isinstance(x, int) and not isinstance(x, bool) for x in (first, count)) \
                and first >= 0 and count >= 1:
            return tuple(range(first, first + count))
    elif isinstance(value, list) and value and all(
            isinstance(s, int) and not isinstance(s, bool) and s >= 0 for s in value):
        if len(set(value)) != len(value):
            raise ConfigError(f"seeds must not repeat, got {value}")
        return tuple(value)
    raise ConfigError(f"seeds must be a non-empty list of whole numbers >= 0 or "
                      f"{{first = F, count = N}}, got {value!r}")


def _conditions(value: Any, what: str) -> tuple[str, ...]:
    if not isinstance(value, list) or not value or any(c not in CONDITIONS for c in value) \
            or len(set(value)) != len(value):
        raise ConfigError(f"{what} must be a non-empty list of distinct conditions from "
                          f"{', '.join(CONDITIONS)}, got {value!r}")
    return tuple(value)


def _changes(value: Any, what: str) -> dict:
    """Config changes by dotted key; their values are checked when the cells' configs are
    built."""
    if not isinstance(value, dict):
        raise ConfigError(f"{what} must be a table of dotted config keys, got {value!r}")
    known = {item.key for item in SETTINGS}
    unknown = [key for key in value if key not in known]
    if unknown:
        raise ConfigError(f"{what}: unknown setting(s) {', '.join(unknown)} (all settings: "
                          "econet evolve --help)")
    reserved = [key for key in value if key in RESERVED]
    if reserved:
        raise ConfigError(f"{what}: {', '.join(reserved)} is set by the spec's own "
                          "'conditions' and 'generations'")
    return dict(value)


def _factors(value: Any) -> list[dict]:
    """The crossed factor levels, as a list of change sets (one empty set without factors)."""
    if not isinstance(value, dict):
        raise ConfigError(f"factors must be a table of dotted config key = [levels], got "
                          f"{value!r}")
    for key, levels in value.items():
        if not isinstance(levels, list) or not levels:
            raise ConfigError(f"factor '{key}' must list at least one level, got {levels!r}")
        if len(set(map(json.dumps, levels))) != len(levels):
            raise ConfigError(f"factor '{key}' repeats a level: {levels}")
    _changes(value, "factors")
    keys = list(value)
    return [dict(zip(keys, combo)) for combo in itertools.product(*value.values())]


def _cells(named: Any, crossed: list[dict], conditions: tuple[str, ...]) -> list[Cell]:
    if not isinstance(named, dict):
        raise ConfigError(f"cells must be a table of named cells, got {named!r}")
    bases = []
    for name, body in named.items():
        if not isinstance(body, dict) or set(body) - {"set", "conditions", "seeded"}:
            raise ConfigError(f"cell '{name}' takes 'set' (config changes), 'conditions' and "
                              f"'seeded' only, got {body!r}")
        seeded = body.get("seeded", [])
        if not isinstance(seeded, list) or not all(isinstance(k, str) for k in seeded):
            raise ConfigError(f"cell '{name}' seeded must list dotted setting keys (each set "
                              f"to the run's seed), got {seeded!r}")
        changes = _changes(body.get("set", {}), f"cell '{name}' set")
        if set(seeded) & set(changes):
            raise ConfigError(f"cell '{name}' both sets and seeds "
                              f"{', '.join(sorted(set(seeded) & set(changes)))}")
        bases.append((name, changes, _conditions(body.get("conditions", list(conditions)),
                                                 f"cell '{name}' conditions"), tuple(seeded)))
    if not bases:
        bases = [("", {}, conditions, ())]
    cells = []
    for (name, changes, own, seeded), levels in itertools.product(bases, crossed):
        label = "+".join(filter(None, [name] + [f"{k.partition('.')[2]}={_level(v)}"
                                                for k, v in levels.items()])) or "base"
        cells.append(Cell(label, {**changes, **levels}, own, name, tuple(levels.items()),
                          seeded))
    return cells


def _level(value: Any) -> str:
    return value if isinstance(value, str) else json.dumps(value)


def _comparisons(value: Any) -> list[dict]:
    if not isinstance(value, list):
        raise ConfigError("compare must be an array of tables ([[compare]])")
    for item in value:
        if not isinstance(item, dict) or set(item) - {"a", "b", "label"} or not \
                {"a", "b"} <= set(item):
            raise ConfigError(f"each [[compare]] needs a and b (and may have a label), got "
                              f"{item!r}")
        for side in ("a", "b"):
            if not isinstance(item[side], dict) or set(item[side]) - {"cell", "condition"} \
                    or not item[side]:
                raise ConfigError(f"compare {side} must name a cell and/or a condition, got "
                                  f"{item[side]!r}")
    return value


def _check_comparisons(spec: SweepSpec) -> None:
    for item in spec.compare:
        for side in ("a", "b"):
            cell = item[side].get("cell")
            if cell is not None and not any(c.matches(cell) for c in spec.cells):
                names = sorted({c.base or c.name for c in spec.cells})
                raise ConfigError(f"compare names cell '{cell}', which the spec does not have "
                                  f"(cells: {', '.join(names)})")
            condition = item[side].get("condition")
            if condition is not None and condition not in CONDITIONS:
                raise ConfigError(f"compare names condition '{condition}'")


# -- the output folder --------------------------------------------------------------------------
def prepare_folder(spec: SweepSpec, out: Path) -> None:
    """Create OUT with the spec, or check that OUT already holds the same runs (its description
    and rule, which change only what the report says, are brought up to date)."""
    out = Path(out)
    path = out / "sweep.json"
    wanted = json.loads(json.dumps(spec.to_dict()))
    if path.exists():
        try:
            stored = json.loads(path.read_text(encoding="utf-8"))
        except (json.JSONDecodeError, UnicodeDecodeError):
            raise ResultsError(f"{path} is damaged (not JSON); choose another --out") from None
        if _runs_of(stored) != _runs_of(wanted):
            raise ResultsError(f"{out} holds a different sweep ('{stored.get('name')}'); "
                               "choose another --out")
        if stored == wanted:
            return
    out.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(wanted, indent=2, sort_keys=True) + "\n", encoding="utf-8")
    tmp.replace(path)


def _runs_of(stored: dict) -> dict:
    return {key: value for key, value in stored.items() if key not in REPORTING}


def load_sweep(out: Path) -> SweepSpec:
    path = Path(out) / "sweep.json"
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
        if data.get("format") != FORMAT:
            raise ResultsError(f"{path} has format {data.get('format')!r}, this version "
                               f"reads {FORMAT!r}")
        if "rule" not in data:     # its report would silently lack the rule's sections
            raise ResultsError(f"{path} was written before sweeps named their decision rule: "
                               f"run `econet sweep run SPEC --out {out}` once to record it "
                               "(finished runs are not run again)")
        return SweepSpec.from_dict(data)
    except OSError:
        raise ResultsError(f"{out} is not a sweep folder (no sweep.json; make one with "
                           "econet sweep run SPEC --out DIR)") from None
    except (json.JSONDecodeError, KeyError, TypeError, UnicodeDecodeError) as error:
        raise ResultsError(f"{path} is damaged ({error})") from None


def finished(run: Run, out: Path, behaviour: bool) -> bool:
    """Whether a run's folder is complete (all generations, and behaviour rows if recorded)."""
    folder = run.folder(out)
    if not (folder / "run.json").exists():
        return False
    try:
        data = RunData(folder)
    except (ResultsError, OSError, ValueError):
        return False
    if not data.complete:
        return False
    if behaviour:
        path = folder / "behaviour.csv"
        return path.exists() and path.read_bytes().count(b"\n") == data.generations_done + 1
    return True



"""What a sweep runs: its cells (each a set of config changes and its conditions), seeds and
comparisons, read from a specification by spec.py; which runs a comparison pairs; and a column
of the tidy table (outcomes.py) over the seeds, as the report and the rules (rules.py) read it."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ...config import Config

FORMAT = "econet-sweep/1"


@dataclass(frozen=True)
class Cell:
    name: str
    changes: dict          # dotted config key -> value (the cell's own and its factor levels)
    conditions: tuple[str, ...]
    base: str = ""         # the named cell it was crossed from ("" without named cells)
    levels: tuple = ()     # its factor levels, as (dotted key, value) pairs
    seeded: tuple = ()     # dotted keys of settings that take each run's seed (drawn per seed)

    def matches(self, name: str) -> bool:
        """Whether a comparison's cell name means this cell: its own name, or the named cell
        it was crossed from (then the comparison is made at every factor level)."""
        return name in (self.name, self.base)


@dataclass(frozen=True)
class Run:
    cell: str
    condition: str
    seed: int
    config: Config

    def folder(self, out: Path) -> Path:
        return Path(out) / self.cell / self.condition / f"seed-{self.seed:03d}"


@dataclass
class SweepSpec:
    name: str
    generations: int
    seeds: tuple[int, ...]
    cells: list[Cell]
    settings: dict = field(default_factory=dict)
    behaviour: bool = True
    compare: list[dict] = field(default_factory=list)
    description: str = ""
    rule: dict = field(default_factory=dict)    # {} or {"name": a rule (rules.py), its options}

    def config(self, cell: Cell, condition: str, seed: int = 0) -> Config:
        """A run's settings (the cell's seeded settings set to the run's seed)."""
        return Config().replace(**self.settings, **cell.changes, **{
            "evolution.condition": condition, "evolution.generations": self.generations},
            **{key: seed for key in cell.seeded})

    def runs(self) -> list[Run]:
        """Every run, longest first (random movement is the cheapest condition)."""
        runs = [Run(cell.name, condition, seed, self.config(cell, condition, seed))
                for cell in self.cells for condition in cell.conditions for seed in self.seeds]
        return sorted(runs, key=lambda run: run.condition == "random")

    def cell(self, name: str) -> Cell:
        return next(c for c in self.cells if c.name == name)

    def to_dict(self) -> dict:
        return {"format": FORMAT, "name": self.name, "description": self.description,
                "generations": self.generations, "seeds": list(self.seeds),
                "behaviour": self.behaviour, "settings": self.settings,
                "cells": [{"name": c.name, "changes": c.changes,
                           "conditions": list(c.conditions), "base": c.base,
                           "levels": [list(pair) for pair in c.levels],
                           **({"seeded": list(c.seeded)} if c.seeded else {})}
                          for c in self.cells],
                "compare": self.compare, "rule": self.rule}

    @classmethod
    def from_dict(cls, data: dict) -> "SweepSpec":
        cells = [Cell(c["name"], c["changes"], tuple(c["conditions"]), c["base"],
                      tuple(map(tuple, c["levels"])), tuple(c.get("seeded", ())))
                 for c in data["cells"]]
        return cls(data["name"], data["generations"], tuple(data["seeds"]), cells,
                   data["settings"], data["behaviour"], data["compare"], data["description"],
                   data["rule"])


def comparison_pairs(spec: SweepSpec, item: dict) -> list[tuple[tuple[str, str], tuple[str, str]]]:
    """The (cell, condition) pairs a [[compare]] entry stands for. A side without a cell means
    every cell (the same on both sides); a cell named as crossed with factors means each of its
    factor levels, paired with the other side's cell at the same levels; a side without a
    condition means every condition the cell runs (the same on both sides)."""
    a, b = item["a"], item["b"]
    runs = {(c.name, condition) for c in spec.cells for condition in c.conditions}
    pairs = []
    for cell in spec.cells:
        if "cell" in a and not cell.matches(a["cell"]):
            continue
        partner = cell if "cell" not in b else next(
            (c for c in spec.cells if c.matches(b["cell"]) and c.levels == cell.levels), None)
        for condition in cell.conditions:
            if a.get("condition", condition) != condition or partner is None:
                continue
            left = (cell.name, condition)
            right = (partner.name, b.get("condition", condition))
            if right in runs and right != left and (left, right) not in pairs:
                pairs.append((left, right))
    return pairs


def values(rows: list[dict], cell: str, condition: str, column: str,
           seeds: tuple[int, ...]) -> np.ndarray:
    """A column over the seeds, in seed order (NaN where a run is missing)."""
    by_seed = {r["seed"]: r[column] for r in rows
               if r["cell"] == cell and r["condition"] == condition}
    return np.array([by_seed.get(seed, math.nan) for seed in seeds], dtype=float)

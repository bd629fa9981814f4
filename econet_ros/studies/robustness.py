"""E6-M, the pre-registered mutational-robustness assay (docs/preregistrations.md, "E6: discovery
or maintenance, done right"), no evolution: is a large net's holding more fragile under mutation
than its champion's? For every holding source of a transplant folder, mutants of the champion
(its own net), of its padded and of its silenced transplant are drawn by the runs' own mutation
(genome.mutate at the source's settings), each kind from a fresh generator seeded (9661, the
source's seed), so that padded and silenced mutants flip the same bits; every mutant is scored
on the champion's own trials of the source's last generation and holds when it reaches and has
at most one separation per successful trial over them. Writes OUT/robustness.csv (per source and
kind: mutants, holding mutants, share) and OUT/robustness.json (the settings)."""
from __future__ import annotations

import csv
import io
import json
from pathlib import Path

import numpy as np

from ..config import Config
from ..errors import ResultsError
from ..files import write_atomically
from ..genome import mutate
from ..science import holding
from .transplant import (RECORD, Source, champion_genome, larger, own_trials, scored,
                         silenced_genome, sources, transplanted_genome)

TABLE, SETTINGS = "robustness.csv", "robustness.json"
STREAM = 9661                 # the registered generator seed: (STREAM, the source's seed)
MUTANTS = 200
KINDS = {"champion": (False, champion_genome), "padded": (True, transplanted_genome),
         "silenced": (True, silenced_genome)}       # kind: (in the larger net, its genome)
COLUMNS = ("seed", "kind", "mutants", "holding", "share")
NATURAL = "natural"   # kinds "natural SWEEP/CELL": large nets' own holders, beside E6-M


def mutants(config: Config, genome: np.ndarray, n: int, rng: np.random.Generator) -> np.ndarray:
    """n mutated copies of the genome, as the runs breed them (genome.mutate at the settings)."""
    e = config.evolution
    return mutate(rng, np.repeat(genome[None], n, axis=0), e.bits_per_weight, e.mutation_rate,
                  e.mutation_mode, e.mutation_step, e.genome_code)


def holding_flags(source: Source, config: Config, genomes: np.ndarray) -> np.ndarray:
    """Per genome: whether it reaches and holds (holding.kind of its separations per
    successful trial) on the champion's own trials of the source's last generation."""
    measures = scored(config, genomes, own_trials(source))
    shape = (len(genomes), config.evolution.trials)
    separations, successes = (np.reshape(v, shape) for v in (measures.separations,
                                                             measures.success))
    return np.array([holding.kind(holding.per_success(s, k)) == holding.HOLDS
                     for s, k in zip(separations, successes)])


def mutant_row(source: Source, config: Config, genome: np.ndarray, kind: str, n: int) -> dict:
    """The row of N mutants of GENOME in CONFIG's net, drawn from the registered generator:
    how many of them hold and their share."""
    drawn = mutants(config, genome, n, np.random.default_rng([STREAM, source.seed]))
    held = int(holding_flags(source, config, drawn).sum())
    return {"seed": source.seed, "kind": kind, "mutants": n, "holding": held, "share": held / n}


def assay(source: Source, units: tuple[int, int, int], n: int = MUTANTS) -> list[dict]:
    """One holding source's rows: per kind, its mutants, how many hold and their share."""
    rows = []
    for kind, (in_larger, genome_of) in KINDS.items():
        config = larger(source.config, units) if in_larger else source.config
        rows.append(mutant_row(source, config, genome_of(source, config), kind, n))
    return rows


def natural_rows(folders: list[Path], units: tuple[int, int, int], n: int = MUTANTS
                 ) -> list[dict]:
    """Rows for the champion of every holding run of the sweeps whose net is UNITS (a large net
    that found holding from random genomes), mutated and scored in its own net as a champion
    is; its kind names the sweep and cell, so that runs of one seed in two sweeps stay apart."""
    rows = []
    for folder in map(Path, folders):
        for source in sources(folder):
            net = source.config.network
            if not source.holds or (net.visual_hidden, net.proprio_hidden,
                                    net.intermodal_hidden) != tuple(units):
                continue
            kind = f"{NATURAL} {folder.name}/{source.folder.parent.parent.name}"
            rows.append(mutant_row(source, source.config,
                                   champion_genome(source, source.config), kind, n))
    return rows


def read_record(folder: Path) -> dict:
    """The transplant record of a folder made by econet sweep transplant (ResultsError if none)."""
    path = Path(folder) / RECORD
    if not path.is_file():
        raise ResultsError(f"{folder} holds no {RECORD}: expected a folder made by econet sweep "
                           f"transplant")
    return json.loads(path.read_text())


def run_robustness(folder: Path, out: Path, n: int = MUTANTS, natural: list[Path] = ()
                   ) -> list[dict]:
    """The assay for every holding source of a transplant folder, and for the natural holders
    of the large net in the sweeps NATURAL; returns the rows written."""
    record = read_record(folder)
    units = tuple(record["into"])
    holders = {r["seed"] for r in record["runs"] if r["source_holds"]}
    rows = [row for source in sources(Path(record["source"])) if source.seed in holders
            for row in assay(source, units, n)] + natural_rows(natural, units, n)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    table = io.StringIO()
    writer = csv.DictWriter(table, COLUMNS, lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    write_atomically(out / TABLE, table.getvalue())
    settings = {"transplant": str(folder), "source": record["source"], "into": list(units),
                "mutants": n, "generator": [STREAM, "source seed"], "kinds": list(KINDS),
                "natural": [str(f) for f in natural]}
    write_atomically(out / SETTINGS, json.dumps(settings, indent=1) + "\n")
    return rows


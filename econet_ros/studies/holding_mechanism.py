"""E5, what holding is (docs/preregistrations.md, "E5: what holding is", registered 2026-12-07
before any champion's activations were read): the units have no biases, so an output rests at
exactly 0.5 (eye still, flexor equal to extensor) when every unit of the last hidden layer
feeding it is silent. A champion *silences its last layer on touch* when, over its
last-generation trials replayed exactly, the median over its contact cycles (observation touch
= 1) of the largest last-layer activation is below THRESHOLD. E5 predicts that most holding
champions silence, and more often than brushing ones. ROS-free."""
from __future__ import annotations

import argparse
import csv
import math
from pathlib import Path

import numpy as np

from ..controllers import Controller, FeedForwardNetwork
from ..errors import ResultsError
from ..evolution import generation_setups, genome_weights
from ..plugins import make_controller
from ..provenance import dirty_warning, made_with
from ..run_folders import RunData, run_code
from ..science import holding
from ..science.stats import share, share_difference
from ..science.sweeps.outcomes import run_holding
from ..science.verdicts import MOST, Criterion, decide
from ..trials import run_trials
from ..world import World

THRESHOLD = 0.05                 # a tenth of a unit's rest (0.5): logistic(-2.94)
THRESHOLD_READINGS = (0.02, 0.1)  # read beside the registered verdict, never instead of it
SHARE_GAP_MARGIN = 0.2           # holders - brushers: a smaller gap in share does not matter
COLUMNS = ("run", "architecture", "class", "contact_cycles", "median_largest_on_contact",
           "replay_fitness", "stored_fitness")
TABLE, SUMMARY = "champions.csv", "summary.md"
# The registered data, by the name of the folder that holds each (a sweep's or a study's).
REGISTERED_DATA = ("e1-width", "e1-range", "e3-modularity", "e2-onset-long",
                   "e2-onset-population", "e4")
NETWORKED = ("normal", "three-layer")      # random movement has no last hidden layer


# -- activations -------------------------------------------------------------------------------
def layer_activations(network: FeedForwardNetwork, weights: np.ndarray,
                      inputs: np.ndarray) -> np.ndarray:
    """The whole activation buffer (n, buffer_size) for inputs (n, n_inputs) and per-row weights
    (n, full weight vector): what forward_block computes, in NumPy, so that a hidden layer
    can be read (the engine keeps only the outputs)."""
    inputs = np.asarray(inputs, dtype=float)
    buffer = np.zeros((len(inputs), network.buffer_size))
    buffer[:, :inputs.shape[1]] = inputs
    w = 0
    for start, stop, out, end in network.layers:
        count = (stop - start) * (end - out)
        layer = weights[:, w:w + count].reshape(len(inputs), end - out, stop - start)
        total = np.einsum("nui,ni->nu", layer, buffer[:, start:stop])
        buffer[:, out:end] = 1.0 / (1.0 + np.exp(-total))
        w += count
    return buffer


def last_hidden(network: FeedForwardNetwork) -> slice:
    """The buffer rows of the last hidden layer: the layer the outputs read."""
    start, stop = network.layers[-1, :2]
    return slice(int(start), int(stop))


class ContactRecorder(Controller):
    """The network driving each cycle itself (its own outputs), keeping on every cycle whose
    observation has touch the largest activation of its last hidden layer, per environment."""

    def __init__(self, network: FeedForwardNetwork):
        super().__init__(network.n_envs, network.config)
        self.network = network
        self.largest: list[np.ndarray] = []    # per contact cycle: (largest, environment)

    def act(self, obs) -> np.ndarray:
        touching = np.flatnonzero(obs.touch > 0.5)
        if len(touching):
            weights = np.repeat(self.network.weights, self.network.block, axis=0)[touching]
            buffer = layer_activations(self.network, weights, obs.network_input()[touching])
            self.largest.append(np.column_stack([buffer[:, last_hidden(self.network)]
                                                 .max(axis=1), touching]))
        return self.network.act(obs)

    def on_contact(self) -> np.ndarray:
        """The largest last-layer activation of every contact cycle recorded."""
        return np.concatenate(self.largest)[:, 0] if self.largest else np.zeros(0)


# -- a champion --------------------------------------------------------------------------------
def champion_index(data: RunData, generation: int) -> int:
    """The champion's place in its generation (its trials' places when trials are not shared)."""
    genomes, champion = data.genomes(generation), data.best_genomes()[generation]
    return int(np.flatnonzero((genomes == champion).all(axis=1))[0])


def replay(data: RunData) -> tuple[ContactRecorder, int, int]:
    """The champion of the last generation on that generation's own trials, recorded: the
    recorder, the replay's fitness and the fitness stored for it (equal when exact)."""
    config, last = data.config, data.generations_done - 1
    trials, index = config.evolution.trials, champion_index(data, last)
    network = make_controller(config.evolution.condition, trials, config)
    network.load(genome_weights(config, data.best_genomes()[last][None]))
    recorder = ContactRecorder(network)
    setups = generation_setups(config, data.seed, data.run, last)
    measures, _ = run_trials(World(trials, config.model), recorder,
                             setups.take(np.arange(index * trials, (index + 1) * trials)),
                             config.evolution.cycles)
    return recorder, int(np.sum(measures.fitness)), int(data.fitness()[last][index])


def champion_row(folder: Path, label: str) -> dict:
    """One run's row of E5's table, named LABEL: its class (holding.py, late window), its
    champion's contact cycles and median largest last-layer activation on contact (NaN without
    contact)."""
    data = RunData(folder)
    recorder, fitness, stored = replay(data)
    largest = recorder.on_contact()
    return {"run": label, "architecture": data.config.evolution.condition,
            "class": run_holding(Path(folder), data.config.evolution.generations),
            "contact_cycles": len(largest),
            "median_largest_on_contact": float(np.median(largest)) if len(largest) else math.nan,
            "replay_fitness": fitness, "stored_fitness": stored}


# -- the rule ----------------------------------------------------------------------------------
def silences(row: dict, threshold: float = THRESHOLD) -> float:
    """1.0 when the champion silences its last layer on touch, 0.0 when not, NaN without a
    contact cycle (it cannot be told, and is left out of the shares)."""
    median = row["median_largest_on_contact"]
    return math.nan if not np.isfinite(median) else float(median < threshold)


def flags(rows: list[dict], kind: str, threshold: float = THRESHOLD) -> list[float]:
    return [silences(r, threshold) for r in rows if r["class"] == kind]


def criteria(rows: list[dict], threshold: float = THRESHOLD) -> dict[str, Criterion]:
    """E5-S: most holding champions silence (Clopper-Pearson share above one half); E5-D: the
    share silencing, holders - brushers, above 0 (Newcombe; absent within the margin)."""
    holders, brushers = (flags(rows, kind, threshold) for kind in (holding.HOLDS,
                                                                   holding.BRUSHES))
    return {"E5-S": Criterion("share of holding champions silencing their last layer on touch",
                              share(holders), low=MOST),
            "E5-D": Criterion("share silencing, holders - brushers",
                              share_difference(holders, brushers), low=0.0,
                              margin=SHARE_GAP_MARGIN, null=True)}


def verdict(rows: list[dict], threshold: float = THRESHOLD) -> tuple[str, float]:
    """E5's four-way verdict and its p-value: replicates when both E5-S and E5-D do."""
    return decide(list(criteria(rows, threshold).values()))


# -- the table and the summary -----------------------------------------------------------------
def run_folders(results: list[Path]) -> dict[str, Path]:
    """Every finished run with a network under the given result folders (a sweep's or a
    study's), by label: the result folder's name and the run's path inside it."""
    found = {}
    for result in map(Path, results):
        for record in sorted(result.glob("**/run.json")):
            data = RunData(record.parent)
            if data.complete and data.config.evolution.condition in NETWORKED:
                found[f"{result.name}/{record.parent.relative_to(result)}"] = record.parent
    if not found:
        raise ResultsError(f"no finished run with a network under {', '.join(map(str, results))}")
    return found


def stored_rows(path: Path, name: str) -> list[dict]:
    """The rows of an earlier E5 table (as written by write_table), each run named NAME/run;
    ResultsError (one line) for a missing or damaged table."""
    numbers = ("contact_cycles", "replay_fitness", "stored_fitness")
    try:
        with open(path, newline="", encoding="utf-8") as handle:
            return [{**{c: r[c] for c in COLUMNS}, "run": f"{name}/{r['run']}",
                     "median_largest_on_contact": float(r["median_largest_on_contact"]),
                     **{c: int(r[c]) for c in numbers}} for r in csv.DictReader(handle)]
    except (OSError, KeyError, ValueError, TypeError, csv.Error) as error:
        raise ResultsError(f"{path} is not a readable E5 table ({error!r})") from None


def stored_table(text: str) -> tuple[str, Path]:
    """--stored's NAME=CSV."""
    name, _, path = text.partition("=")
    if not name or not path:
        raise argparse.ArgumentTypeError(f"expected NAME=CSV, e.g. e4=docs/results/e5/"
                                         f"e4-champions.csv, got {text!r}")
    return name, Path(path)


def write_table(rows: list[dict], path: Path) -> None:
    """One line per champion, with its class at the registered threshold (yes/no/n/a)."""
    with open(path, "w", newline="") as out:
        writer = csv.DictWriter(out, [*COLUMNS, "silences"])
        writer.writeheader()
        for row in rows:
            told = silences(row)
            writer.writerow({**row, "silences": "n/a" if math.isnan(told)
                             else ("yes" if told else "no")})


def tally(rows: list[dict], kind: str, threshold: float) -> str:
    told = [f for f in flags(rows, kind, threshold) if not math.isnan(f)]
    return f"{int(sum(told))}/{len(told)}"


def judged_lines(rows: list[dict], label: str, threshold: float) -> list[str]:
    """One table line per hypothesis (E5-S, E5-D) and E5's verdict, for a set of champions."""
    holders, brushers = tally(rows, holding.HOLDS, threshold), tally(rows, holding.BRUSHES,
                                                                     threshold)
    found = criteria(rows, threshold)
    verdict_of, p = verdict(rows, threshold)
    tested = f" (p {p:.3g})" if math.isfinite(p) else ""
    return [f"| {label} | {threshold:g} | {holders} | {brushers} | "
            f"{found['E5-S'].text(four=True)} | {found['E5-D'].text(four=True)} | "
            f"{verdict_of}{tested} |"]


def coverage(rows: list[dict]) -> str:
    """Which of the registered data the table holds: the registered verdict needs all."""
    held = {r["run"].split("/")[0] for r in rows}
    missing = [name for name in REGISTERED_DATA if name not in held]
    if not missing:
        return f"Data: every registered source ({', '.join(REGISTERED_DATA)}).\n"
    return (f"**PARTIAL**: without {', '.join(missing)} (part of the registered data), so this "
            f"is not E5's registered verdict. Held: {', '.join(sorted(held))}.\n")


def summary_markdown(rows: list[dict], runs: list[Path], stored: list[str]) -> list[str]:
    """The verdict at the registered threshold on all champions, then the readings (per
    architecture and source, the other thresholds), and whether every replay was exact."""
    exact = sum(r["replay_fitness"] == r["stored_fitness"] for r in rows)
    architectures = sorted({r["architecture"] for r in rows})
    kept = "".join(f" Rows kept from an earlier table: {s}." for s in stored)
    lines = [*dirty_warning(), "# E5, what holding is: the champions' last hidden layer on "
             "touch\n", coverage(rows), made_with([run_code(r) for r in runs]) + kept + "\n",
             f"Champions: {len(rows)}; replays scoring exactly their stored fitness: {exact} of "
             f"{len(rows)}. Silencing: the median over contact cycles of the largest last-hidden-"
             f"layer activation below the threshold (docs/preregistrations.md, \"E5: what holding "
             f"is\"). Holders and brushers by the runs' late class; x/n counts champions with "
             f"contact.\n", "## The registered rule (threshold 0.05, all champions)\n",
             "| champions | threshold | holders silencing | brushers silencing | E5-S | E5-D | "
             "E5 |", "|---|---|---|---|---|---|---|",
             *judged_lines(rows, "all", THRESHOLD),
             "\n## Readings beside it (not the verdict)\n",
             "| champions | threshold | holders silencing | brushers silencing | E5-S | E5-D | "
             "E5 |", "|---|---|---|---|---|---|---|"]
    for label in ["all", *architectures]:
        chosen = [r for r in rows if label == "all" or r["architecture"] == label]
        for threshold in sorted({THRESHOLD, *THRESHOLD_READINGS}):
            if (label, threshold) != ("all", THRESHOLD):
                lines += judged_lines(chosen, label, threshold)
    for source in sorted({r["run"].split("/")[0] for r in rows}):
        lines += judged_lines([r for r in rows if r["run"].startswith(source + "/")],
                              source, THRESHOLD)
    return lines + [""]


def main(argv: list[str] | None = None) -> None:
    """python -m econet_ros.studies.holding_mechanism --out DIR [--stored NAME=CSV] RESULTS...:
    E5's table (TABLE) and summary (SUMMARY) for the champion of every finished run with a
    network under the result folders (sweeps' or studies'), with the rows of earlier tables
    kept under NAME (a source whose runs are not on this machine)."""
    parser = argparse.ArgumentParser(description=main.__doc__)
    parser.add_argument("results", nargs="*", type=Path)
    parser.add_argument("--stored", action="append", default=[], type=stored_table,
                        metavar="NAME=CSV")
    parser.add_argument("--out", type=Path, required=True)
    args = parser.parse_args(argv)
    if not args.results and not args.stored:
        parser.error("give result folders, --stored NAME=CSV, or both")
    try:
        runs = run_folders(args.results) if args.results else {}
        rows = [row for name, path in args.stored for row in stored_rows(path, name)]
        rows = [champion_row(run, label) for label, run in runs.items()] + rows
    except ResultsError as error:
        parser.error(str(error))
    args.out.mkdir(parents=True, exist_ok=True)
    write_table(rows, args.out / TABLE)
    stored = [f"{name}={path}" for name, path in args.stored]
    (args.out / SUMMARY).write_text("\n".join(summary_markdown(rows, list(runs.values()),
                                                              stored)))


if __name__ == "__main__":
    main()

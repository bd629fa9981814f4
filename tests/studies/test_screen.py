"""E2's screen as a stored result: `econet sweep screen` scores the random genomes of every cell
and seed of a screen spec and stores the table, reproducibly; the experiments' page reads it and
never screens again; the registered spec names its networks, seeds and E2-S's cells."""
import csv
from pathlib import Path

import numpy as np
import pytest

from econet_ros.config import Config
from econet_ros.science.sweeps.spec import load_spec
from econet_ros.studies import experiments, family, screen
from sweep_helpers import screened_into, tiny_screen

SPECS = Path(__file__).resolve().parents[2] / "examples" / "sweeps"


def test_the_screen_scores_random_genomes_of_a_seed_reproducibly():
    config = Config().replace(**{"evolution.trials": 4, "evolution.cycles": 40,
                                 "evolution.parents": 10, "evolution.population": 20})
    a = screen.screen_genomes(config, [9201])
    assert np.array_equal(a, screen.screen_genomes(config, [9201])) and 0 < len(a) <= 20
    assert set(a.tolist()) == {0.0, 1.0}                  # these 20 both hold and brush
    two = screen.screen_genomes(config, [9201, 9202])
    assert np.array_equal(two[:len(a)], a)                # a seed's genomes do not move


@pytest.fixture(scope="module")
def stored(tmp_path_factory) -> Path:
    return screened_into(tiny_screen("e2-screen"), tmp_path_factory.mktemp("screen"))


def test_the_stored_table_holds_what_the_screen_scores(stored):
    screened = screen.read_screen(stored)
    spec = load_spec(stored.parent / "spec.toml")
    for cell in spec.cells:
        config = spec.config(cell, "normal")
        assert np.array_equal(np.sort(screened.flags[cell.name]),
                              np.sort(screen.screen_genomes(config, spec.seeds)))
    text = "\n".join(screen.screen_markdown(screened))
    assert "E2-S: holding share of random genomes, large - small" in text
    assert "Beside it, small - large:" in text and screened.seeds == "9201-9202"


def test_every_genome_is_stored_with_its_scores_and_counts_to_the_table(stored):
    """A referee can judge the screen again by another holding criterion from the genomes'
    successful trials and separations."""
    with open(stored / screen.GENOMES, newline="") as handle:
        genomes = list(csv.DictReader(handle))
    with open(stored / screen.TABLE, newline="") as handle:
        table = list(csv.DictReader(handle))
    for row in table:
        mine = [g for g in genomes if (g["cell"], g["seed"]) == (row["cell"], row["seed"])]
        assert len(mine) == int(row["genomes"])
        assert sum(g["kind"] != "does not reach" for g in mine) == int(row["reach"])
        assert sum(g["kind"] == "holds" for g in mine) == int(row["hold"])
        assert all(g["kind"] == screen.genome_kind(float(g["successes"]), float(g["separations"]))
                   for g in mine)


def test_the_page_reads_the_stored_screen_and_never_screens(stored, tmp_path, monkeypatch):
    def no_screening(*args):
        raise AssertionError("the page ran the screen")
    monkeypatch.setattr(screen, "screen_genomes", no_screening)
    text = family.experiments_page([stored], tmp_path / "page").read_text()
    assert "| E2-S |" in text and "seeds 9201-9202" in text


def test_the_registered_screen_names_its_networks_seeds_and_e2_s_cells():
    spec = load_spec(SPECS / "e2-screen.toml")
    assert [c.name for c in spec.cells] == ["2/2/4", "4/4/8", "three-layer 4", "three-layer 8"]
    assert spec.seeds == tuple(range(9201, 9211)) and spec.rule["large"] == "4/4/8"
    assert {r.config.evolution.population for r in spec.runs()} == {200}
    assert experiments.FAMILY.count("E2-S") == 1

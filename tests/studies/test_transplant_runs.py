"""E2's transplant arm: a holding small net's champion laid out in a larger net scores exactly
what the champion does, the larger net's run starts from copies of it (the control from the
run's own random genomes), finished runs resume, and a source without an exact zero is refused
in one line."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from econet_ros.cli import main
from econet_ros.evolution import initial_genomes
from econet_ros.run_folders import RunData
from econet_ros.runs import evolve_into
from econet_ros.science import holding
from econet_ros.studies import transplant
from sweep_helpers import evolved_sweep

SOURCE = '''
name = "source"
generations = 3
seeds = [11, 12]
behaviour = false

[settings]
"evolution.population" = 8
"evolution.parents" = 2
"evolution.trials" = 3
"evolution.cycles" = 40
"evolution.genome_code" = "CODE"

[cells.small]
set = {"network.visual_hidden" = 2, "network.proprio_hidden" = 2, "network.intermodal_hidden" = 4}
conditions = ["normal"]
'''


def source_sweep(folder: Path, code: str = "sign-magnitude") -> Path:
    """A finished tiny source sweep, evolved in process (no Ray)."""
    return evolved_sweep(SOURCE.replace("CODE", code), folder)


@pytest.fixture(scope="module")
def source(tmp_path_factory) -> Path:
    return source_sweep(tmp_path_factory.mktemp("transplant"))


def test_a_transplanted_champion_scores_exactly_what_it_did(source):
    for found in transplant.sources(source):
        target = transplant.larger(found.config, (4, 4, 8))
        codes = transplant.transplanted_genome(found, target)
        assert codes.shape == (8 * 4 + 4 * 4 + (1 + 4 + 4 + 5) * 8,)
        assert transplant.behaves_alike(found, target, codes)
        changed = codes ^ np.uint8(0b0100_0000)     # every weight moved by about half the range
        assert not transplant.behaves_alike(found, target, changed)


def test_transplanted_runs_start_from_the_champion_and_controls_from_random_genomes(
        source, tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(transplant, "run_holding", lambda folder, generations: holding.HOLDS)
    out = tmp_path / "moved"
    assert main(["sweep", "transplant", str(source), "--out", str(out), "--quiet"]) == 0
    record = json.loads((out / transplant.RECORD).read_text())
    assert [r["seed"] for r in record["runs"]] == [11, 12]
    assert all(r["behaves_alike"] and r["source_holds"] for r in record["runs"])
    assert "2 holding source run(s); runs holding late by arm: transplanted 2, control 2" in capsys.readouterr().out
    for found in transplant.sources(source):
        target = transplant.larger(found.config, (4, 4, 8))
        moved = RunData(out / "transplanted" / f"seed-{found.seed:03d}")
        control = RunData(out / "control" / f"seed-{found.seed:03d}")
        assert moved.complete and control.complete
        first = moved.genomes(0)
        assert (first == transplant.transplanted_genome(found, target)).all()
        assert np.array_equal(control.genomes(0), initial_genomes(
            target, len(first[0]), found.seed, 1))
    made = {p: p.read_bytes() for p in out.rglob("*.npy")}
    tested = []
    monkeypatch.setattr(transplant, "evolve_into", lambda *args, **kw: evolve_into(
        *args, **kw, on_generation=lambda result, offspring: tested.append(result.generation)))
    assert main(["sweep", "transplant", str(source), "--out", str(out), "--quiet"]) == 0
    assert tested == [] and {p: p.read_bytes() for p in out.rglob("*.npy")} == made


def test_sources_that_brush_are_not_transplanted(source, tmp_path, monkeypatch):
    monkeypatch.setattr(transplant, "run_holding", lambda folder, generations: holding.BRUSHES)
    record = transplant.run_transplants(source, tmp_path / "none")
    assert [r["source_holds"] for r in record["runs"]] == [False, False]
    assert not (tmp_path / "none" / "transplanted").exists()
    assert len(transplant.kept_flags(record)) == 0


@pytest.mark.parametrize("argv, fragment", [
    (["--into", "4/4"], "expected V/P/I positive whole numbers"),
    (["--into", "1/1/2"], "every layer of the large network must be at least as wide"),
])
def test_bad_targets_are_one_line_errors(source, tmp_path, monkeypatch, capsys, argv, fragment):
    monkeypatch.setattr(transplant, "run_holding", lambda folder, generations: holding.HOLDS)
    assert main(["sweep", "transplant", str(source), "--out", str(tmp_path / "x"), *argv]) == 2
    err = capsys.readouterr().err
    assert fragment in err and err.count("\n") == 1


def test_a_source_without_an_exact_zero_is_refused_in_one_line(tmp_path, monkeypatch, capsys):
    binary = source_sweep(tmp_path, "binary")
    monkeypatch.setattr(transplant, "run_holding", lambda folder, generations: holding.HOLDS)
    assert main(["sweep", "transplant", str(binary), "--out", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err
    assert "needs a genome code with an exact zero" in err and err.count("\n") == 1

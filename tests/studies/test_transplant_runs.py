"""E2's and E6's transplant arms: a holding small net's champion laid out in a larger net scores
exactly what the champion does, padded or with its added units silenced by touch, the larger
net's run starts from copies of it (E2's control from the run's own random genomes, E6's
continued arm from the champion in its own net), finished runs resume, and a source without an
exact zero is refused in one line; E6's robustness assay scores mutants of those genomes."""
from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from econet_ros.cli import main
from econet_ros.controllers import FourLayerNetwork
from econet_ros.controllers import transplant as transplant_weights
from econet_ros.evolution import genome_weights, initial_genomes
from econet_ros.run_folders import RunData
from econet_ros.runs import evolve_into
from econet_ros.science import holding
from econet_ros.studies import robustness, transplant
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


# -- E6's arms and its robustness assay -------------------------------------------------------
def test_the_silenced_transplant_codes_minus_r_at_each_added_units_touch_weight_only(source):
    for found in transplant.sources(source):
        target = transplant.larger(found.config, (4, 4, 8))
        codes = transplant.silenced_genome(found, target)
        weights = genome_weights(target, codes)
        r = target.evolution.weight_range
        # 4/4/8: the intermodal layer's weights start at 8 * 4 + 4 * 4 = 48, 9 a unit, touch
        # first; the added units are 4..7
        added_touch = [48 + 9 * unit for unit in range(4, 8)]
        assert list(transplant.added_touch_weights(found, target)) == added_touch
        assert (weights[added_touch] == -r).all() and (codes[added_touch] == 0xFF).all()
        small = FourLayerNetwork(1, found.config)
        kept = transplant_weights(small, FourLayerNetwork(1, target),
                                  np.ones(small.n_params)) == 1
        padded = genome_weights(target, transplant.transplanted_genome(found, target))
        assert np.flatnonzero(weights != padded).tolist() == added_touch
        assert np.flatnonzero(~kept & (weights != 0)).tolist() == added_touch
        assert transplant.behaves_alike(found, target, codes)


def test_e6_arms_start_from_the_padded_silenced_and_own_champion(source, tmp_path, monkeypatch,
                                                                   capsys):
    monkeypatch.setattr(transplant, "run_holding", lambda folder, generations: holding.HOLDS)
    out = tmp_path / "e6"
    assert main(["sweep", "transplant", str(source), "--out", str(out), "--quiet",
                 "--arms", "padded,silenced,continued"]) == 0
    record = json.loads((out / transplant.RECORD).read_text())
    assert record["arms"] == ["padded", "silenced", "continued"]
    assert transplant.arms_of(record) == ("padded", "silenced", "continued")
    assert all(r["behaves_alike"] and r["padded"] == r["silenced"] == r["continued"]
               == holding.HOLDS for r in record["runs"])
    assert "padded 2, silenced 2, continued 2" in capsys.readouterr().out
    assert not (out / "transplanted").exists() and not (out / "control").exists()
    for found in transplant.sources(source):
        target = transplant.larger(found.config, (4, 4, 8))
        first = {arm: RunData(out / arm / f"seed-{found.seed:03d}").genomes(0)
                 for arm in record["arms"]}
        assert (first["padded"] == transplant.transplanted_genome(found, target)).all()
        assert (first["silenced"] == transplant.silenced_genome(found, target)).all()
        assert (first["continued"] == transplant.champion(found)[1]).all()
        assert len(first["continued"]) == found.config.evolution.population


def test_an_unknown_arm_is_refused_in_one_line(source, tmp_path, capsys):
    assert main(["sweep", "transplant", str(source), "--out", str(tmp_path / "x"),
                 "--arms", "padded,grafted"]) == 2
    err = capsys.readouterr().err
    assert "unknown arm(s) grafted" in err and err.count("\n") == 1


def transplant_folder(source: Path, folder: Path) -> Path:
    """A transplant record naming every run of the source as holding (no arm run: the assay
    reads only the sources and the larger net)."""
    folder.mkdir()
    runs = [{"seed": s.seed, "source": str(s.folder), "source_holds": True}
            for s in transplant.sources(source)]
    record = {"source": str(source), "into": [4, 4, 8], "arms": list(transplant.E6_ARMS),
              "runs": runs}
    (folder / transplant.RECORD).write_text(json.dumps(record))
    return folder


def test_the_assay_stores_a_share_per_source_and_kind_and_repeats_itself(source, tmp_path):
    folder = transplant_folder(source, tmp_path / "moved")
    rows = robustness.run_robustness(folder, tmp_path / "a", n=5)
    assert [(r["seed"], r["kind"]) for r in rows] == [
        (s, k) for s in (11, 12) for k in ("champion", "padded", "silenced")]
    assert all(0 <= r["share"] <= 1 and r["share"] == r["holding"] / 5 for r in rows)
    robustness.run_robustness(folder, tmp_path / "b", n=5)
    assert ((tmp_path / "a" / robustness.TABLE).read_bytes()
            == (tmp_path / "b" / robustness.TABLE).read_bytes())
    assert json.loads((tmp_path / "a" / robustness.SETTINGS).read_text())["mutants"] == 5


def test_padded_and_silenced_mutants_flip_the_same_bits(source):
    found = transplant.sources(source)[0]
    target = transplant.larger(found.config, (4, 4, 8))
    padded, silenced = (transplant.transplanted_genome(found, target),
                        transplant.silenced_genome(found, target))
    flips = [robustness.mutants(target, g, 7, np.random.default_rng([9661, found.seed])) ^ g
             for g in (padded, silenced)]
    assert np.array_equal(*flips) and flips[0].any()


def test_without_mutation_every_mutant_holds_as_its_genome_does(source):
    for found in transplant.sources(source):
        still = replace(found, config=found.config.replace(**{"evolution.mutation_rate": 0.0}))
        champion = transplant.champion(still)[1]
        drawn = robustness.mutants(still.config, champion, 4, np.random.default_rng(0))
        assert (drawn == champion).all()
        own = float(robustness.holding_flags(still, still.config, champion[None])[0])
        assert [r["share"] for r in robustness.assay(still, (4, 4, 8), 4)] == [own] * 3


def test_the_assay_of_a_folder_without_a_record_is_refused_in_one_line(tmp_path, capsys):
    assert main(["sweep", "robustness", str(tmp_path), "--out", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err
    assert "holds no transplant.json" in err and err.count("\n") == 1


def test_the_robustness_verb_prints_e6_m_with_silenced_beside(source, tmp_path, capsys):
    folder = transplant_folder(source, tmp_path / "moved")
    assert main(["sweep", "robustness", str(folder), "--out", str(tmp_path / "r"),
                 "--mutants", "3"]) == 0
    said = capsys.readouterr().out
    assert "2 holding source(s)" in said and "silenced - champion: median" in said
    assert "E6-M: holding share of mutants, padded - champion = " in said
    assert said.count("padded - champion") == 1
    assert (tmp_path / "r" / robustness.TABLE).read_text().count("\n") == 1 + 2 * 3


def test_natural_holders_of_the_large_net_are_assayed_in_their_own_net(source, tmp_path,
                                                                        monkeypatch):
    """Rows of kind "natural SWEEP/CELL" for every holding run whose net is the larger one
    (here the tiny sweep's own 2/2/4), its champion's mutants scored as a champion's are."""
    found = [replace(s, holds=True) for s in transplant.sources(source)]
    monkeypatch.setattr(robustness, "sources", lambda folder: found)
    rows = robustness.natural_rows([source], (2, 2, 4), n=4)
    champions = robustness.assay(found[0], (4, 4, 8), 4)
    assert [(r["seed"], r["kind"]) for r in rows] == [
        (11, f"natural {source.name}/small"), (12, f"natural {source.name}/small")]
    assert rows[0]["share"] == champions[0]["share"]     # same genome, generator and trials
    assert robustness.natural_rows([source], (4, 4, 8), n=4) == []

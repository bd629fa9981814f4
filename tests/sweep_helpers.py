"""Sweep and screen folders made in process, without Ray, for the tests that read them."""
from __future__ import annotations

from pathlib import Path

from econet_ros.cli import main
from econet_ros.runs import evolve_into
from econet_ros.science.sweeps.spec import load_spec, prepare_folder


def evolved_sweep(spec_text: str, folder: Path) -> Path:
    """Every run of the spec evolved one after another into FOLDER/<the spec's name>, as
    econet sweep run lays them out."""
    (folder / "spec.toml").write_text(spec_text)
    spec = load_spec(folder / "spec.toml")
    out = folder / spec.name
    prepare_folder(spec, out)
    for run in spec.runs():
        evolve_into(run.folder(out), run.config, run.seed, 1)
    return out


def tiny_screen(rule: str) -> str:
    """A screen spec under RULE (e2-screen, e6-screen): two nets, two seeds of 20 genomes, four
    short trials; seconds to screen."""
    return f"""
name = "tiny-screen"
seeds = [9201, 9202]
behaviour = false
[settings]
"evolution.population" = 20
"evolution.parents" = 10
"evolution.trials" = 4
"evolution.cycles" = 40
[cells.small]
set = {{"network.visual_hidden" = 2, "network.proprio_hidden" = 2, "network.intermodal_hidden" = 4}}
[cells.large]
set = {{"network.visual_hidden" = 4, "network.proprio_hidden" = 4, "network.intermodal_hidden" = 8}}
[[compare]]
label = "small - large"
a = {{cell = "small"}}
b = {{cell = "large"}}
[rule]
name = "{rule}"
large = "large"
small = "small"
"""


def screened_into(spec_text: str, folder: Path) -> Path:
    """FOLDER/out, screened by econet sweep screen from the spec, written to FOLDER/spec.toml."""
    (folder / "spec.toml").write_text(spec_text)
    assert main(["sweep", "screen", str(folder / "spec.toml"), "--out", str(folder / "out")]) == 0
    return folder / "out"

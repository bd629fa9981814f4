"""Sweep folders made in process, without Ray, for the tests that read them."""
from __future__ import annotations

from pathlib import Path

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

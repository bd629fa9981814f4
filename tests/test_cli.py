"""The econet command line: one-line errors before any work, help, and a small real run."""
import subprocess
import sys

import pytest

from econet_ros.cli import main
from econet_ros.runs import RunData


@pytest.mark.parametrize("arguments, fragment", [
    (["--condition", "five-layer"], "invalid choice: 'five-layer'"),
    (["--population", "20", "--parents", "30"], "parents must be between 1 and the population"),
    (["--trials", "-3"], "trials must be at least 1"),
    (["--generations", "0"], "evolution.generations must be at least 1, got 0"),
    (["--runs", "0"], "argument --runs: must be a whole number of at least 1, got 0"),
    (["--seed", "-1"], "argument --seed: must be a whole number of at least 0, got -1"),
    (["--set", "model.object_radius=-1"], "model.object_radius must be between"),
    (["--set", "evolution.population=abc"], "evolution.population must be a whole number"),
    (["--set", "evolution.shared_trials=no"], "evolution.shared_trials must be true or false"),
    (["--set", "model.object_radius=1e309"], "model.object_radius must be a finite number"),
    (["--population", "many"], "argument --population: invalid int value: 'many'"),
    (["--start-posture", "crouched"], "invalid choice: 'crouched'"),
    (["--set", "model.colour=3"], "unknown setting 'model.colour'"),
    (["--config", "/nonexistent/settings.json"], "cannot read config"),
])
def test_bad_input_is_one_line_before_any_work(tmp_path, capsys, arguments, fragment):
    out = tmp_path / "results"
    status = main(["evolve", "--out", str(out), "--quiet", *arguments])
    err = capsys.readouterr().err
    assert status == 2
    assert err.count("\n") == 1 and err.startswith("econet: error:"), err
    assert fragment in err
    assert not out.exists() or not any(out.iterdir())


def test_unwritable_output_folder_is_refused(tmp_path, capsys):
    blocker = tmp_path / "a-file"
    blocker.write_text("not a folder")
    status = main(["evolve", "--out", str(blocker / "results"), "--quiet"])
    err = capsys.readouterr().err
    assert status == 2 and "cannot write to output folder" in err and err.count("\n") == 1


def test_results_with_other_settings_are_not_overwritten_silently(tmp_path, capsys):
    small = ["evolve", "--out", str(tmp_path), "--quiet", "--runs", "1", "--generations", "2",
             "--population", "10", "--parents", "2", "--trials", "2", "--cycles", "10"]
    assert main(small) == 0
    assert main(small[:-1] + ["12"]) == 2
    assert "different settings" in capsys.readouterr().err
    assert main(small[:-1] + ["12", "--overwrite"]) == 0
    assert RunData(tmp_path / "run-01").config.evolution.cycles == 12


def test_evolve_writes_run_folders_and_says_where(tmp_path, capsys):
    status = main(["evolve", "--out", str(tmp_path), "--quiet", "--runs", "2",
                   "--generations", "3", "--population", "10", "--parents", "2",
                   "--trials", "3", "--cycles", "20", "--seed", "4"])
    assert status == 0
    assert str(tmp_path.resolve()) in capsys.readouterr().out
    for run in (1, 2):
        data = RunData(tmp_path / f"run-{run:02d}")
        assert data.complete and data.seed == 4 and data.run == run
        assert data.fitness().shape == (3, 10)


def test_help_explains_the_command():
    result = subprocess.run([sys.executable, "-m", "econet_ros", "evolve", "--help"],
                            capture_output=True, text=True, check=True)
    for option in ("--condition", "--runs", "--generations", "--seed", "--out", "--set",
                   "--object-radius", "--mutation-mode", "--visual-hidden"):
        assert option in result.stdout
    # the help text of a setting comes from its config field, with its origin and range
    assert "(assumption; between 0.001 and 50)" in " ".join(result.stdout.split())


def test_options_override_the_config_file_only_when_given(tmp_path, capsys):
    settings = tmp_path / "settings.json"
    settings.write_text('{"evolution": {"population": 8, "parents": 2, "trials": 2, '
                        '"cycles": 5, "generations": 2}, "model": {"object_radius": 3}}')
    assert main(["evolve", "--out", str(tmp_path / "r"), "--quiet", "--runs", "1",
                 "--config", str(settings), "--cycles", "6"]) == 0
    config = RunData(tmp_path / "r" / "run-01").config
    assert (config.evolution.population, config.evolution.cycles) == (8, 6)
    assert config.model.object_radius == 3.0

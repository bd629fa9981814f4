"""The econet command line: help, small real runs, and refusing to mix settings in one folder
(bad input of every kind: test_reliability.py)."""
import subprocess
import sys


from econet_ros.cli import main
from econet_ros.run_folders import RunData


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


def test_a_named_command_loads_only_its_own_module(tmp_path):
    """`econet evolve` must not pay for the analysis stack's imports (about 3 s); --help of all
    commands still lists every one."""
    code = ("import sys\nfrom econet_ros.cli import main\n"
            f"assert main(['evolve', '--out', {str(tmp_path)!r}, '--quiet', '--runs', '1', "
            "'--generations', '1', '--population', '10', '--parents', '2', '--trials', '2', "
            "'--cycles', '5']) == 0\n"
            "print(sorted(m for m in ('scipy.stats', 'matplotlib', 'econet_ros.science') "
            "if m in sys.modules))\n")
    loaded = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            check=True).stdout.strip().splitlines()[-1]
    assert loaded == "[]"
    listing = subprocess.run([sys.executable, "-m", "econet_ros", "--help"], capture_output=True,
                             text=True, check=True).stdout
    assert "{evolve,study,analyze,sweep,check,compare,evaluate,bag}" in listing

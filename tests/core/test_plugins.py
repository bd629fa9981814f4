"""Plug-ins by name, controllers above all: setup.cfg's registrations as installed and as read from
a source tree, the hand-written reacher, a controller from a
package outside econet_ros (tests/plugin_example) through the command line, and one-line errors
for names that do not resolve (the same through the nodes: tests/nodes/test_plugin_nodes.py)."""
import os
import subprocess
import sys
from importlib.metadata import distribution

import numpy as np
import pytest

from econet_ros.cli import main
from econet_ros.config import Config
from econet_ros.plugins import GROUP, SETUP_CFG, declared
from econet_ros.trials import run_trials
from econet_ros.world import World, sample_setups

from graph_helpers import REPO

PLUGIN_DIR = REPO / "tests" / "plugin_example"


def with_plugin_env() -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = f"{PLUGIN_DIR}{os.pathsep}{env.get('PYTHONPATH', '')}"
    return env


def test_installed_metadata_registers_what_setup_cfg_declares():
    """Every group the installed metadata has (an install older than the checkout may lack a
    newer group: scripts/setup brings it up to date) holds exactly setup.cfg's names."""
    installed = {}
    for ep in distribution("econet_ros").entry_points:
        installed.setdefault(ep.group, {})[ep.name] = ep.value
    assert GROUP in installed
    assert all(names == declared(group) for group, names in installed.items())


def test_setup_cfg_declares_the_controllers_and_the_command(tmp_path):
    assert declared(GROUP)["normal"] == "econet_ros.controllers:FourLayerNetwork"
    assert declared("console_scripts")["econet"] == "econet_ros.cli:main"
    assert declared(GROUP, tmp_path / "missing.cfg") == {} and SETUP_CFG.exists()


def test_reacher_reaches_the_object_in_most_trials():
    config = Config()
    n = 60
    world = World(n, config.model)
    from econet_ros.plugins import make_controller
    measures, _ = run_trials(world, make_controller("reacher", n, config),
                             sample_setups(np.random.default_rng(11), n, config.model), 100)
    assert measures.success.mean() >= 0.75, measures.success.mean()
    assert measures.fitness.mean() > 30     # it stays on the object once there


@pytest.mark.parametrize("name, fragment", [
    ("nope", "unknown controller 'nope': not a registered name"),
    ("no_such_module_xyz:Thing", "cannot import module 'no_such_module_xyz'"),
    ("econet_ros.reacher:Missing", "has no 'Missing'"),
    ("os:getcwd", "is not a subclass of econet_ros.controllers.Controller"),
    ("econet_ros.controllers:Controller", "does not implement act"),
])
def test_bad_controller_names_are_one_line_errors(capsys, name, fragment):
    status = main(["evaluate", "--controller", name, "--trials", "2"])
    err = capsys.readouterr().err
    assert status == 2
    assert err.count("\n") == 1 and err.startswith("econet: error:"), err
    assert fragment in err


def test_outside_package_controller_through_the_command_line(tmp_path):
    run = lambda *args, env=None: subprocess.run(  # noqa: E731
        [sys.executable, "-m", "econet_ros", *args], cwd=REPO, env=env, capture_output=True,
        text=True, timeout=120)
    evaluated = run("evaluate", "--controller", "example-linear", "--trials", "4", "--cycles",
                    "10", env=with_plugin_env())
    assert evaluated.returncode == 0, evaluated.stderr
    assert "econet_plugin_example:LinearController" in evaluated.stdout
    assert "success      " in evaluated.stdout

    out = tmp_path / "evolved"
    evolved = run("evolve", "--controller", "example-linear", "--runs", "1", "--generations",
                  "2", "--population", "4", "--parents", "2", "--trials", "2", "--cycles", "10",
                  "--quiet", "--out", str(out), env=with_plugin_env())
    assert evolved.returncode == 0, evolved.stderr
    assert '"controller": "example-linear"' in (out / "run-01" / "controller.json").read_text()
    assert np.load(out / "run-01" / "genomes.npy").shape == (3, 4, 65)   # the plug-in's size

    missing = run("evaluate", "--controller", "example-linear")      # not on the path
    assert missing.returncode == 2
    assert missing.stderr.count("\n") == 1 and "unknown controller 'example-linear'" in \
        missing.stderr

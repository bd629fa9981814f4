"""`pip install .` without ROS: the core goes into a fresh venv (no system site-packages) with
the dependencies setup.py declares, at the versions requirements.txt pins, and no ROS wheel; a
tiny `econet evolve` runs there (its kernels compiled afresh), `econet check` (the reference
model, a package of its own) is there, and the commands that need what the core does not bring
say in one line what to install. The tests marked `install` take about
a minute and a half, most of it numba compiling the trial kernel; deselect them with
-m "not install". The others check the same one-line contract in this process."""
import csv
import importlib.util
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from econet_ros.cli import main, nodes
from econet_ros.cli.main import missing_dependency

REPO = Path(__file__).resolve().parents[2]
# What setup.py builds from; copied, so that the build leaves nothing in the checkout.
SOURCES = ("setup.py", "setup.cfg", "package.xml", "resource", "launch", "econet_ros",
           "econet_msgs")
SMOKE_SWEEP = REPO / "examples" / "sweeps" / "smoke.toml"
EVOLUTION = {"population": 4, "parents": 2, "trials": 2, "cycles": 5, "generations": 2}


def plain_environment(**extra: str) -> dict[str, str]:
    """This process's environment without what scripts/env.sh adds (the checkout and the ROS
    install space on PYTHONPATH, the setup venv), so nothing leaks into the fresh venv."""
    env = {key: value for key, value in os.environ.items()
           if key not in ("PYTHONPATH", "VIRTUAL_ENV", "AMENT_PREFIX_PATH", "CMAKE_PREFIX_PATH",
                          "LD_LIBRARY_PATH", "PYTHONHOME")}
    return {**env, **extra}


@pytest.fixture(scope="module")
def venv(tmp_path_factory):
    """A fresh venv holding `pip install .` of the checkout (pip from this venv installs into
    it, so the new one needs no pip of its own); removed afterwards (about 0.5 GB)."""
    root = tmp_path_factory.mktemp("install")
    source = root / "source"
    source.mkdir()
    for name in SOURCES:
        if (REPO / name).is_dir():
            shutil.copytree(REPO / name, source / name,
                            ignore=shutil.ignore_patterns("__pycache__"))
        else:
            shutil.copy2(REPO / name, source / name)
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", root / "venv"], check=True)
    pip = subprocess.run([sys.executable, "-m", "pip", "--python", root / "venv" / "bin" / "python",
                          "install", "--no-input", "--no-compile", "--disable-pip-version-check",
                          "-c", REPO / "requirements.txt", source],
                         capture_output=True, text=True, env=plain_environment(), timeout=600)
    assert pip.returncode == 0, pip.stdout[-2000:] + pip.stderr[-2000:]
    yield root / "venv"
    shutil.rmtree(root)


def run(venv: Path, *command: str, cwd: Path) -> subprocess.CompletedProcess:
    env = plain_environment(PATH=f"{venv / 'bin'}{os.pathsep}{os.environ['PATH']}",
                            NUMBA_CACHE_DIR=str(cwd / "numba-cache"))
    return subprocess.run([str(venv / "bin" / command[0]), *command[1:]], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=600)


@pytest.mark.install
def test_the_core_installs_with_its_dependencies_and_without_ros(venv, tmp_path):
    listing = subprocess.run([sys.executable, "-m", "pip", "--python", venv / "bin" / "python",
                              "list", "--format", "json", "--disable-pip-version-check"],
                             capture_output=True, text=True, check=True, env=plain_environment())
    installed = {entry["name"].lower().replace("_", "-")
                 for entry in json.loads(listing.stdout)}
    assert {"econet-ros", "numpy", "numba", "scipy", "matplotlib", "tqdm", "cma"} <= installed
    assert not [name for name in installed if name.startswith("ros-") or name == "rclpy"]
    where = run(venv, "python", "-c",
                "import importlib.util, econet_ros; print(econet_ros.__file__); "
                "print(importlib.util.find_spec('rclpy'))", cwd=tmp_path)
    module, rclpy = where.stdout.split()
    assert Path(module).is_relative_to(venv) and rclpy == "None"


@pytest.mark.install
def test_a_tiny_evolve_runs_in_the_fresh_install(venv, tmp_path):
    options = [item for key, value in EVOLUTION.items() for item in (f"--{key}", str(value))]
    result = run(venv, "econet", "evolve", "--out", "out", "--runs", "1", "--quiet", *options,
                 cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    folder = tmp_path / "out" / "run-01"
    assert json.loads((folder / "run.json").read_text())["config"]["evolution"].items() \
        >= EVOLUTION.items()
    rows = list(csv.DictReader((folder / "metrics.csv").open()))
    assert [int(row["generation"]) for row in rows] == list(range(EVOLUTION["generations"]))
    check = run(venv, "python", "-c",
                "import numpy as np; f = np.load('out/run-01/fitness.npy'); "
                "g = np.load('out/run-01/genomes.npy'); print(*f.shape, *g.shape[:2], "
                "int(f.min()), int(f.max()))", cwd=tmp_path)
    generations, population, stored, genomes, low, high = map(int, check.stdout.split())
    assert (generations, population) == (EVOLUTION["generations"], EVOLUTION["population"])
    assert (stored, genomes) == (EVOLUTION["generations"] + 1, EVOLUTION["population"])
    assert 0 <= low <= high <= EVOLUTION["trials"] * EVOLUTION["cycles"]


@pytest.mark.install
def test_the_check_comes_with_the_install(venv, tmp_path):
    helped = run(venv, "econet", "check", "--help", cwd=tmp_path)
    assert helped.returncode == 0 and "reference model" in helped.stdout, helped.stderr
    refused = run(venv, "econet", "check", "no-sweep", cwd=tmp_path)
    assert refused.returncode == 2
    assert one_line(refused.stderr).startswith("econet: error: no-sweep is not a sweep folder")


@pytest.mark.install
@pytest.mark.parametrize("command, needs", [
    (("world_node",), "ROS 2 (rclpy)"),
    (("viewer_node",), "ROS 2 (rclpy)"),
    (("econet", "sweep", "run", str(SMOKE_SWEEP), "--out", "s"), 'pip install ".[sweep]"'),
    (("econet", "evolve", "--device", "cuda", "--out", "e"), 'pip install ".[cuda]"'),
])
def test_what_the_core_lacks_is_named_in_one_line(venv, tmp_path, command, needs):
    result = run(venv, *command, cwd=tmp_path)
    assert result.returncode == 2
    assert needs in result.stderr and len(result.stderr.strip().splitlines()) == 1, result.stderr


def one_line(text: str) -> str:
    lines = text.strip().splitlines()
    assert len(lines) == 1, text
    return lines[0]


def test_a_missing_extra_ends_the_command_in_one_line_naming_the_extra(monkeypatch, capsys,
                                                                       tmp_path):
    monkeypatch.setitem(sys.modules, "ray", None)       # import ray: ModuleNotFoundError
    assert main(["sweep", "run", str(SMOKE_SWEEP), "--out", str(tmp_path / "s")]) == 2
    assert one_line(capsys.readouterr().err) == \
        'econet: error: econet sweep needs Ray: pip install ".[sweep]" in the checkout'


def test_a_node_script_without_ros_says_so_in_one_line(monkeypatch, capsys):
    find_spec = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec",
                        lambda name, *rest: None if name == "rclpy" else find_spec(name, *rest))
    assert nodes.world_node() == 2
    assert "world_node needs ROS 2 (rclpy)" in one_line(capsys.readouterr().err)


def test_a_module_that_is_no_optional_dependency_stays_a_traceback():
    error = ModuleNotFoundError("No module named 'numpy'", name="numpy")
    with pytest.raises(ModuleNotFoundError) as raised:
        missing_dependency(error, "econet evolve")
    assert raised.value is error

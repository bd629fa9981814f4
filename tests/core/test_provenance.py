"""Which code made a result: a fresh `econet evolve` run folder records its commit, dirty flag,
versions and session; outside a git checkout (an installed package, or no git) the commit is
"unknown" without an error; commits of a checkout, its dirty tree, and whether a registration
precedes the runs, on a small git repository made here. (Resumed runs: test_runs.py.)"""
import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from econet_ros import provenance
from econet_ros.cli import main
from econet_ros.provenance import UNKNOWN, git_state, made_with, registration
from econet_ros.run_folders import PROVENANCE_FILE, read_sessions, run_code

REPO = Path(__file__).resolve().parents[2]
TINY = ["--runs", "1", "--population", "4", "--parents", "2", "--trials", "2", "--cycles", "5",
        "--generations", "2", "--quiet"]


def git(folder: Path, *args: str) -> str:
    return subprocess.run(["git", "-C", str(folder), "-c", "user.name=t", "-c",
                           "user.email=t@example.org", *args], capture_output=True, text=True,
                          check=True).stdout.strip()


@pytest.fixture
def history(tmp_path):
    """A git repository with two commits: (folder, first commit, second commit)."""
    folder = tmp_path / "repo"
    folder.mkdir()
    git(folder, "init", "-q")
    commits = []
    for text in ("one", "two"):
        (folder / "file.txt").write_text(text)
        git(folder, "add", "file.txt")
        git(folder, "commit", "-q", "-m", text)
        commits.append(git(folder, "rev-parse", "HEAD"))
    return folder, *commits


def test_a_fresh_evolve_run_folder_records_its_code_and_one_session(tmp_path):
    assert main(["evolve", "--out", str(tmp_path), *TINY]) == 0
    record = json.loads((tmp_path / "run-01" / PROVENANCE_FILE).read_text())
    assert record["format"] == "econet-provenance/1"
    [session] = record["sessions"]
    assert session["commit"] == UNKNOWN or re.fullmatch("[0-9a-f]{40}", session["commit"])
    assert session["commit"] == git_state(REPO)[0]          # this checkout's, or unknown
    assert session["dirty"] in (True, False, None)
    assert session["dirty"] is None or session["commit"] != UNKNOWN
    assert {"python", "econet_ros", "numpy", "numba"} <= set(session["versions"])
    assert session["versions"]["numpy"] == __import__("numpy").__version__
    assert session["first_generation"] == 0
    assert session["started"] <= session["ended"]
    assert run_code(tmp_path / "run-01") == (session["commit"], session["dirty"])


def test_a_finished_run_run_again_keeps_its_record(tmp_path):
    assert main(["evolve", "--out", str(tmp_path), *TINY]) == 0
    before = (tmp_path / "run-01" / PROVENANCE_FILE).read_bytes()
    assert main(["evolve", "--out", str(tmp_path), *TINY]) == 0
    assert (tmp_path / "run-01" / PROVENANCE_FILE).read_bytes() == before


def test_a_damaged_record_is_one_line_naming_it_and_its_removal_lets_the_run_go_on(
        tmp_path, capsys):
    assert main(["evolve", "--out", str(tmp_path), *TINY]) == 0
    metrics = tmp_path / "run-01" / "metrics.csv"
    metrics.write_bytes(b"".join(metrics.read_bytes().splitlines(keepends=True)[:2]))
    record = tmp_path / "run-01" / PROVENANCE_FILE
    record.write_text('{"format": "econet-provenance/1", "sessions": {}}')
    assert main(["evolve", "--out", str(tmp_path), *TINY]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"{record} is damaged" in err and "remove it" in err, err
    record.unlink()
    assert main(["evolve", "--out", str(tmp_path), *TINY]) == 0
    [session] = read_sessions(tmp_path / "run-01")
    assert session["first_generation"] == 1


def test_a_folder_from_before_provenance_has_no_recorded_code(tmp_path):
    assert read_sessions(tmp_path) == [] and run_code(tmp_path) == ("", None)
    assert "no recorded commit" in made_with([run_code(tmp_path)])


def run_python(code: str, cwd: Path, **env: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", code], cwd=cwd, capture_output=True,
                          text=True, timeout=60, env={**os.environ, **env})


PRINT_CODE = ("import json; from econet_ros import provenance; "
              "print(json.dumps({**provenance.code(), 'file': provenance.__file__}))")


def test_outside_a_git_checkout_the_commit_is_unknown_without_error(tmp_path):
    installed = tmp_path / "site-packages"           # the package as pip would install it
    shutil.copytree(REPO / "econet_ros", installed / "econet_ros",
                    ignore=shutil.ignore_patterns("__pycache__"))
    done = run_python(PRINT_CODE, installed)
    assert done.returncode == 0 and done.stderr == "", done.stderr
    found = json.loads(done.stdout)
    assert found["file"].startswith(str(installed))
    assert found["commit"] == UNKNOWN and found["dirty"] is None
    assert found["versions"]["numpy"]
    no_git = run_python(PRINT_CODE, REPO, PATH=str(tmp_path))      # a checkout, but no git
    assert no_git.returncode == 0 and no_git.stderr == "", no_git.stderr
    assert json.loads(no_git.stdout)["commit"] == UNKNOWN
    assert git_state(tmp_path) == (UNKNOWN, None)
    # code shipped to a Ray cluster's workers carries the driver's commit
    shipped = json.dumps({"commit": "ab" * 20, "dirty": False})
    done = run_python(PRINT_CODE, installed, **{provenance.SHIPPED: shipped})
    assert json.loads(done.stdout)["commit"] == "ab" * 20


def test_a_checkout_gives_its_commit_and_whether_its_tree_is_dirty(history):
    folder, _, second = history
    assert git_state(folder) == (second, False)
    (folder / "file.txt").write_text("changed")
    assert git_state(folder) == (second, True)
    (folder / "sub").mkdir()
    assert git_state(folder / "sub") == (UNKNOWN, None)        # not the top of the checkout


def test_a_registration_is_checked_against_every_run_commit(history):
    folder, first, second = history
    said = registration(first, [second, first, f"{first} {second}"], folder)
    assert said.startswith(f"Pre-registered at commit `{first[:12]}`")
    assert "ancestor of the commits of 3 of its 3 run(s)." in said
    said = registration(second, [second, first, "", UNKNOWN, "ab" * 20], folder)
    assert "of 1 of its 5 run(s); **not** of 1; 3 cannot be checked here" in said
    outside = registration(first, [second], folder.parent)      # no checkout to ask
    assert "of 0 of its 1 run(s); 1 cannot be checked here" in outside


def test_a_report_line_names_its_code_and_its_runs_code():
    line = made_with([("ab" * 20, False), ("ab" * 20, True), ("ab" * 20, False), ("", None)],
                     ["", "Pre-registered at commit `x`."])
    me = provenance.code()
    assert line.startswith("**Code**: this report was made with ")
    assert ("an unknown commit" if me["commit"] == UNKNOWN else me["commit"][:12]) in line
    assert ("its 4 run(s) with `abababababab` (2), `abababababab` with uncommitted changes (1), "
            "no recorded commit (made before run folders recorded their code) (1).") in line
    assert line.endswith(". Pre-registered at commit `x`.")

"""econet sweep: the specification's one-line errors, runs on local Ray equal to runs made in
process, resuming, a killed worker, a two-node cluster without a shared result folder, the
provenance the workers record, and the report's tables."""
from __future__ import annotations

import csv
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pytest

from econet_ros.cli import main
from econet_ros.provenance import code
from econet_ros.run_folders import PROVENANCE_FILE, read_sessions
from econet_ros.science.study import evolve_with_behaviour
from econet_ros.science.sweeps.spec import load_spec

REPO = Path(__file__).resolve().parents[3]

TINY = '''
name = "tiny"
generations = 3
seeds = [4, 5]
conditions = ["normal", "three-layer"]

[settings]
"evolution.population" = 8
"evolution.parents" = 2
"evolution.trials" = 2
"evolution.cycles" = 20

[cells.narrow]
set = {"network.visual_hidden" = 2}

[cells.gray]
set = {"evolution.genome_code" = "gray", "evolution.mutation_mode" = "weights"}
conditions = ["normal"]

[[compare]]
a = {condition = "normal"}
b = {condition = "three-layer"}

[[compare]]
a = {cell = "gray", condition = "normal"}
b = {cell = "narrow", condition = "normal"}
'''


def write_spec(folder: Path, text: str = TINY, name: str = "spec.toml") -> Path:
    path = folder / name
    path.write_text(text)
    return path


def folder_bytes(folder: Path) -> dict[str, bytes]:
    """A run folder's result files (not its lock file, nor its provenance: when it was made)."""
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir())
            if not p.name.startswith(".") and p.name != PROVENANCE_FILE}


def assert_made_by_one_session_of_this_code(folder: Path) -> None:
    """The run's provenance, recorded by the worker that evolved it, travelled with its files."""
    [session] = read_sessions(folder)
    assert session["first_generation"] == 0 and session["started"] <= session["ended"]
    assert (session["commit"], session["dirty"]) == (code()["commit"], code()["dirty"])


def in_process(spec_path: Path, tmp: Path) -> dict[tuple, dict[str, bytes]]:
    """Every run of the spec evolved here, one after another, as econet study does."""
    spec = load_spec(spec_path)
    made = {}
    for run in spec.runs():
        folder = tmp / "inproc" / run.cell / run.condition / str(run.seed)
        evolve_with_behaviour([(folder, 1)], run.config, run.seed)
        made[run.cell, run.condition, run.seed] = folder_bytes(folder)
    return made


@pytest.mark.parametrize("text, fragment", [
    (TINY.replace('"network.visual_hidden" = 2', '"network.colour" = 2'),
     "unknown setting(s) network.colour"),
    (TINY.replace('"network.visual_hidden" = 2', '"network.visual_hidden" = -2'),
     "cell 'narrow', normal: network.visual_hidden must be between 1 and 256, got -2"),
    (TINY + '\n[factors]\n"evolution.mutation_rate" = []\n',
     "factor 'evolution.mutation_rate' must list at least one level"),
    (TINY + '\n[cells.narrow]\nset = {}\n', "is not valid TOML: Cannot declare"),
    (TINY.replace("seeds = [4, 5]", 'seeds = ["4", 5]'), "seeds must be a non-empty list"),
    (TINY.replace("seeds = [4, 5]", "seeds = [4, 4]"), "seeds must not repeat"),
    (TINY.replace('name = "tiny"', 'name = "tiny"\nruns = 3'), "unknown key(s) runs"),
    (TINY.replace('b = {cell = "narrow"', 'b = {cell = "wide"'),
     "compare names cell 'wide', which the spec does not have"),
    (TINY.replace('"evolution.cycles" = 20', '"evolution.generations" = 20'),
     "evolution.generations is set by the spec's own"),
    (TINY.replace('seeds = [4, 5]', 'seeds = [4, 5]\nrule = "best"'),
     "rule must be one of confirmatory, e1-range, e1-width"),
])
def test_bad_specs_are_one_line_errors_before_any_run(tmp_path, capsys, text, fragment):
    out = tmp_path / "out"
    status = main(["sweep", "run", str(write_spec(tmp_path, text)), "--out", str(out),
                   "--quiet"])
    err = capsys.readouterr().err
    assert status == 2 and err.count("\n") == 1 and err.startswith("econet: error:"), err
    assert fragment in err, err
    assert not out.exists() or not any(out.iterdir())


def test_unreachable_cluster_and_a_folder_of_another_sweep_are_refused(tmp_path, capsys):
    spec = write_spec(tmp_path)
    started = time.monotonic()
    assert main(["sweep", "run", str(spec), "--out", str(tmp_path / "a"), "--address",
                 "127.0.0.1:9", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "no Ray cluster answers at 127.0.0.1:9" in err and err.count("\n") == 1
    assert time.monotonic() - started < 10
    other = tmp_path / "other"
    other.mkdir()
    (other / "sweep.json").write_text(json.dumps({"format": "econet-sweep/1", "name": "x"}))
    assert main(["sweep", "run", str(spec), "--out", str(other), "--quiet"]) == 2
    assert "holds a different sweep ('x')" in capsys.readouterr().err


@pytest.fixture(scope="module")
def swept(tmp_path_factory):
    """The tiny sweep run once on local Ray with two workers, and the same runs in process."""
    tmp = tmp_path_factory.mktemp("sweep")
    spec = write_spec(tmp)
    assert main(["sweep", "run", str(spec), "--out", str(tmp / "out"), "--workers", "2",
                 "--quiet"]) == 0
    return spec, tmp / "out", in_process(spec, tmp)


def test_sweep_runs_equal_runs_made_in_process(swept):
    spec_path, out, made = swept
    spec = load_spec(spec_path)
    assert len(made) == 2 * 2 + 2          # narrow: both conditions; gray: normal only
    for run in spec.runs():
        got = folder_bytes(run.folder(out))
        assert set(got) == {"run.json", "metrics.csv", "genomes.npy", "fitness.npy",
                            "best_genomes.npy", "behaviour.csv"}
        assert got == made[run.cell, run.condition, run.seed], run
        assert_made_by_one_session_of_this_code(run.folder(out))
    config = json.loads((out / "gray" / "normal" / "seed-004" / "run.json").read_text())
    assert config["config"]["evolution"]["genome_code"] == "gray"


def test_a_second_call_skips_finished_runs_and_redoes_unfinished_ones(swept, tmp_path):
    spec_path, out, made = swept
    copy = tmp_path / "out"
    subprocess.run(["cp", "-a", str(out), str(copy)], check=True)
    torn = copy / "narrow" / "normal" / "seed-005" / "metrics.csv"
    torn.write_bytes(torn.read_bytes()[:-9])                     # a crash mid-row
    gone = copy / "narrow" / "three-layer" / "seed-004"
    subprocess.run(["rm", "-r", str(gone)], check=True)
    untouched = copy / "gray" / "normal" / "seed-005" / "genomes.npy"
    before = untouched.stat().st_mtime_ns
    assert main(["sweep", "run", str(spec_path), "--out", str(copy), "--quiet"]) == 0
    for run in load_spec(spec_path).runs():
        assert folder_bytes(run.folder(copy)) == made[run.cell, run.condition, run.seed]
        assert_made_by_one_session_of_this_code(run.folder(copy))  # a redone run: from scratch
    assert untouched.stat().st_mtime_ns == before


def test_a_folder_from_before_rules_is_refused_until_run_again(swept, tmp_path, capsys):
    """Its report would lack the rule's sections without a word; a re-run records the rule and
    runs nothing again."""
    spec_path, out, _ = swept
    copy = tmp_path / "old"
    shutil.copytree(out, copy)
    stored = json.loads((copy / "sweep.json").read_text())
    del stored["rule"]
    (copy / "sweep.json").write_text(json.dumps(stored))
    assert main(["sweep", "report", str(copy)]) == 2
    err = capsys.readouterr().err
    assert "before sweeps named their decision rule" in err and err.count("\n") == 1
    assert main(["sweep", "run", str(spec_path), "--out", str(copy), "--quiet"]) == 0
    assert "rule" in json.loads((copy / "sweep.json").read_text())
    assert main(["sweep", "report", str(copy)]) == 0


def test_report_tables_pair_runs_by_seed(swept, capsys):
    _, out, _ = swept
    assert main(["sweep", "report", str(out)]) == 0
    with open(out / "outcomes.csv") as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == 6
    assert {"cell", "condition", "seed", "top_fitness_late", "top_latency_success_early",
            "top_separations_per_success_late", "top_eye_speed_fix_late"} <= set(rows[0])
    dirty = code()["dirty"]
    assert {(r["commit"], r["dirty"]) for r in rows} == {
        (code()["commit"], "" if dirty is None else str(dirty))}
    with open(out / "comparisons.csv") as handle:
        compared = list(csv.DictReader(handle))
    within = [r for r in compared if r["a"] == "narrow/normal" and r["outcome"] ==
              "top_fitness" and r["window"] == "late"]
    assert len(within) == 1 and within[0]["b"] == "narrow/three-layer"
    late = {(r["cell"], r["condition"], int(r["seed"])): float(r["top_fitness_late"])
            for r in rows}
    diffs = [late["narrow", "normal", s] - late["narrow", "three-layer", s] for s in (4, 5)]
    assert float(within[0]["mean_difference"]) == pytest.approx(np.mean(diffs))
    assert int(within[0]["a_above_b"]) == sum(d > 0 for d in diffs)
    assert {r["b"] for r in compared if r["a"] == "gray/normal"} == {"narrow/normal"}
    assert (out / "figures" / "outcomes.png").stat().st_size > 0
    summary = (out / "summary.md").read_text()
    assert "Paired comparisons" in summary and "its 6 run(s) with " in summary


KILL = TINY.replace("generations = 3", "generations = 25").replace(
    '"evolution.cycles" = 20', '"evolution.cycles" = 60').replace(
    '"evolution.population" = 8', '"evolution.population" = 40').replace(
    "seeds = [4, 5]", "seeds = [6]").split("[cells.narrow]")[0]


def parent(pid: int) -> int:
    """A process's parent (0 once gone): field 4 of /proc/PID/stat, after the command's ')'."""
    try:
        return int(Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[1])
    except (OSError, IndexError, ValueError):
        return 0


def running_tasks(driver: int) -> list[int]:
    """The Ray workers running a sweep task that descend from this driver process: only the
    test's own sweep (other sweeps on the machine are not this test's to kill)."""
    pids = []
    for entry in Path("/proc").iterdir():
        try:
            if entry.name.isdigit() and b"ray::evolve_run" in (entry / "cmdline").read_bytes():
                pids.append(int(entry.name))
        except OSError:
            pass
    return [pid for pid in pids if descends(pid, driver)]


def descends(pid: int, ancestor: int) -> bool:
    while pid > 1:
        pid = parent(pid)
        if pid == ancestor:
            return True
    return False


def test_a_worker_killed_mid_run_is_retried_and_the_results_do_not_change(tmp_path):
    spec = write_spec(tmp_path, KILL)
    out = tmp_path / "out"
    sweep = subprocess.Popen([sys.executable, "-m", "econet_ros", "sweep", "run", str(spec),
                              "--out", str(out), "--workers", "1", "--quiet"], cwd=REPO,
                             stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    deadline, killed = time.monotonic() + 120, None
    while killed is None and time.monotonic() < deadline and sweep.poll() is None:
        pids = running_tasks(sweep.pid)
        if pids:
            time.sleep(0.5)                                    # well into the run
            os.kill(pids[0], signal.SIGKILL)
            killed = pids[0]
        time.sleep(0.05)
    output, _ = sweep.communicate(timeout=300)
    assert killed is not None, "never saw a running task"
    assert sweep.returncode == 0, output
    made = in_process(spec, tmp_path)
    for run in load_spec(spec).runs():
        assert folder_bytes(run.folder(out)) == made[run.cell, run.condition, run.seed]


def test_a_two_node_cluster_without_a_shared_folder_gives_the_local_results(swept, tmp_path):
    from ray.cluster_utils import Cluster

    spec_path, _, made = swept
    head, second = (tempfile.mkdtemp(prefix=f"econet-{name}-", dir="/tmp")   # short: sockets
                    for name in ("head", "second"))
    cluster = Cluster(initialize_head=True, head_node_args={
        "num_cpus": 1, "temp_dir": head, "include_dashboard": False})
    try:
        cluster.add_node(num_cpus=1, temp_dir=second)
        cluster.wait_for_nodes()
        out = tmp_path / "out"
        assert main(["sweep", "run", str(spec_path), "--out", str(out), "--address",
                     cluster.address, "--quiet"]) == 0
        for run in load_spec(spec_path).runs():
            assert folder_bytes(run.folder(out)) == made[run.cell, run.condition, run.seed]
            assert_made_by_one_session_of_this_code(run.folder(out))     # the shipped code's
        # both nodes worked, and neither left a result behind: the driver wrote them all
        assert len({p.name for p in Path(second).glob("session_*/logs/worker-*.out")}) > 0
        assert not list(Path(second).rglob("metrics.csv"))
    finally:
        cluster.shutdown()
        for folder in (head, second):
            shutil.rmtree(folder, ignore_errors=True)


def test_compare_pairs_sweep_cells_by_seed_and_refuses_a_bare_study(swept, tmp_path, capsys):
    _, out, _ = swept
    assert main(["sweep", "report", str(out)]) == 0          # outcomes.csv, to check against
    a, b = out / "narrow" / "normal", out / "gray" / "normal"
    table = tmp_path / "compared.csv"
    assert main(["compare", str(a), str(b), "--csv", str(table)]) == 0
    assert "paired by run" in capsys.readouterr().out
    with open(table) as handle:
        rows = {(r["outcome"], r["window"]): r for r in csv.DictReader(handle)}
    with open(out / "outcomes.csv") as handle:
        late = {(r["cell"], int(r["seed"])): float(r["top_fitness_late"])
                for r in csv.DictReader(handle) if r["condition"] == "normal"}
    diffs = [late["narrow", s] - late["gray", s] for s in (4, 5)]
    assert float(rows["top_fitness", "late"]["difference"]) == pytest.approx(np.mean(diffs))
    assert rows["top_fitness", "late"]["paired"] == "True"
    assert main(["compare", str(out), str(a)]) == 2
    assert "holds no run folders" in capsys.readouterr().err


def test_a_published_sweep_carries_its_summary_tables_and_figures(swept, tmp_path):
    from econet_ros.science.report import publish_sweep
    _, out, _ = swept
    target = publish_sweep(out, tmp_path / "sweeps")
    assert target == tmp_path / "sweeps" / "tiny"
    assert (target / "summary.md").read_text() == (out / "summary.md").read_text()
    assert (target / "outcomes.csv").read_bytes() == (out / "outcomes.csv").read_bytes()
    for link in ("figures/outcomes.png", "figures/gallery.png"):        # the summary's links
        assert link in (target / "summary.md").read_text() and (target / link).is_file()

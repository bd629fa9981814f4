"""Reliability of the command line and the result files (docs/reliability.md lists every case):
each kind of bad input is refused in one line with exit status 2 before any work (or repaired
with results unchanged), and a fault while writing (a full disk, a kill, a second writer)
keeps every finished generation: the resumed files are byte-identical to an undisturbed run's.

The full-disk tests use a real, small tmpfs when this process may mount one (root) and
otherwise simulate ENOSPC in the write calls; both kinds run where they can."""
import errno
import json
import os
import shutil
import signal
import subprocess
import sys
import time
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest

from econet_ros import run_folders
from econet_ros.cli import main
from econet_ros.config import Config
from econet_ros.errors import UsageError
from econet_ros.files import locked
from econet_ros.run_folders import RunData, RunStore
from econet_ros.runs import evolve_into
from econet_ros.science import report as report_module
from econet_ros.science.study import StudySpec, load_study, run_study

SMALL = ["--runs", "1", "--population", "4", "--parents", "2", "--trials", "2", "--cycles", "5",
         "--quiet"]
TINY = [*SMALL, "--generations", "4"]
LONG = [*SMALL, "--generations", "150"]     # metrics.csv outgrows its first 4 KiB page
RUN_FILES = ("run.json", "metrics.csv", "genomes.npy", "fitness.npy", "best_genomes.npy")


def refused(capsys, status: int, fragment: str) -> str:
    """The error a command printed, checked to be one line, exit status 2, naming fragment."""
    err = capsys.readouterr().err
    assert status == 2, err
    assert err.startswith("econet: error: ") and err.count("\n") == 1, err
    assert "Traceback" not in err and fragment in err, err
    return err


def assert_same_run(folder: Path, reference: Path) -> None:
    for name in RUN_FILES:
        assert (folder / name).read_bytes() == (reference / name).read_bytes(), name


def snapshot(folder: Path) -> dict:
    return {p.relative_to(folder): p.read_bytes() for p in sorted(folder.rglob("*"))
            if p.is_file()}


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """Undisturbed runs to compare with: {"tiny": run folder, "long": run folder}."""
    out = tmp_path_factory.mktemp("reference")
    for name, options in (("tiny", TINY), ("long", LONG)):
        assert main(["evolve", "--out", str(out / name), *options]) == 0
    return {name: out / name / "run-01" for name in ("tiny", "long")}


# -- settings and the command line --------------------------------------------------------------
CONFIG_FILES = [
    (b"[1, 2]", "a config must be a JSON object of sections"),
    (b"3", "a config must be a JSON object of sections (model, network, evolution), got int"),
    (b'{"evolution": {"population": "100"}}', "evolution.population must be a whole number"),
    (b'{"evolution": {"population": [100]}}', "evolution.population must be a whole number"),
    (b'{"model": 3}', "config section 'model' must be a JSON object"),
    (b"", "is not valid JSON"),
    (b"\xff\xfe{}", "is not valid JSON"),
    (None, "cannot read config"),              # no such file
    ("folder", "cannot read config"),          # a folder in its place
]


@pytest.mark.parametrize("arguments, fragment", [
    (["--condition", "five-layer"], "invalid choice: 'five-layer'"),
    (["--population", "20", "--parents", "30"], "parents must be between 1 and the population"),
    (["--trials", "-3"], "trials must be at least 1"),
    (["--generations", "0"], "evolution.generations must be at least 1, got 0"),
    (["--runs", "0"], "argument --runs: must be a whole number of at least 1, got 0"),
    (["--set", "model.object_radius=-1"], "model.object_radius must be between"),
    (["--population", "many"], "argument --population: invalid int value: 'many'"),
    (["--start-posture", "crouched"], "invalid choice: 'crouched'"),
    (["--set", "model.colour=3"], "unknown setting 'model.colour'"),
    (["--set", "evolution.population=abc"], "evolution.population must be a whole number"),
    (["--set", "model.object_radius=null"], "object_radius must be a finite number, got None"),
    (["--set", 'model.field_of_view_deg="wide"'], "field_of_view_deg must be a finite number"),
    (["--set", "model.object_radius=1e309"], "model.object_radius must be a finite number"),
    (["--set", 'evolution.shared_trials="no"'], "evolution.shared_trials must be true or false"),
    (["--seed", "-1"], "argument --seed: must be a whole number of at least 0, got -1"),
], ids=["condition", "parents-over-population", "trials-negative", "generations-0", "runs-0",
        "radius-negative", "population-text", "start-posture", "unknown-setting",
        "population-abc", "radius-null", "fov-text", "radius-1e309", "shared-trials-no",
        "seed-negative"])
def test_bad_settings_are_one_line_before_any_work(tmp_path, capsys, arguments, fragment):
    out = tmp_path / "results"
    refused(capsys, main(["evolve", "--out", str(out), *TINY, *arguments]), fragment)
    assert not out.exists()


@pytest.mark.parametrize("option", ["--seed", "--noise-seed"])
def test_negative_seeds_of_evaluate_are_one_line(capsys, option):
    status = main(["evaluate", "--controller", "random", "--trials", "2", option, "-1"])
    refused(capsys, status, f"argument {option}: must be a whole number of at least 0")


@pytest.mark.parametrize("content, fragment", CONFIG_FILES,
                         ids=["list", "number", "text-for-number", "list-for-number",
                              "section-number", "empty", "not-utf8", "missing", "folder"])
def test_bad_config_files_are_one_line(tmp_path, capsys, content, fragment):
    path = tmp_path / "settings.json"
    if content == "folder":
        path.mkdir()
    elif content is not None:
        path.write_bytes(content)
    out = tmp_path / "results"
    refused(capsys, main(["evolve", "--out", str(out), "--config", str(path), *TINY]), fragment)
    assert not out.exists()


# -- damaged run folders, met by a resume -------------------------------------------------------
def _empty_run_json_before_any_generation(run: Path) -> None:
    (run / "run.json").write_bytes(b"")          # what a crash during creation once left
    metrics = run / "metrics.csv"
    metrics.write_bytes(metrics.read_bytes().splitlines(keepends=True)[0])


def _torn_metrics_row(run: Path) -> None:
    metrics = run / "metrics.csv"
    metrics.write_bytes(metrics.read_bytes()[:-9])


REPAIRED = {"empty-run-json-unstarted": _empty_run_json_before_any_generation,
            "torn-metrics-row": _torn_metrics_row}

REFUSED = {
    "torn-run-json": (lambda run: (run / "run.json").write_bytes(b'{"format": "econet-ru'),
                      "run.json is damaged"),
    "run-json-a-list": (lambda run: (run / "run.json").write_text("[]"),
                        "run.json is damaged (not a JSON object)"),
    "metrics-missing": (lambda run: (run / "metrics.csv").unlink(), "metrics.csv is missing"),
    "metrics-other-columns": (lambda run: (run / "metrics.csv").write_text("gen,fit\r\n"),
                              "metrics.csv has columns from another version"),
    "genomes-truncated": (lambda run: os.truncate(run / "genomes.npy", 200),
                          "genomes.npy is truncated or not a NumPy array file"),
    "controller-json-torn": (lambda run: (run / "controller.json").write_text('{"contr'),
                             "controller.json"),
}


def damaged_copy(reference: Path, tmp_path: Path, damage) -> Path:
    out = tmp_path / "results"
    shutil.copytree(reference.parent, out)
    damage(out / "run-01")
    return out


@pytest.mark.parametrize("damage", REPAIRED.values(), ids=REPAIRED.keys())
def test_what_a_crash_leaves_is_repaired_with_results_unchanged(tmp_path, reference, damage):
    out = damaged_copy(reference["tiny"], tmp_path, damage)
    assert main(["evolve", "--out", str(out), *TINY]) == 0
    assert_same_run(out / "run-01", reference["tiny"])


@pytest.mark.parametrize("damage, fragment", REFUSED.values(), ids=REFUSED.keys())
def test_a_damaged_run_folder_is_refused_untouched(tmp_path, capsys, reference, damage,
                                                   fragment):
    out = damaged_copy(reference["tiny"], tmp_path, damage)
    before = snapshot(out)
    refused(capsys, main(["evolve", "--out", str(out), *TINY]), fragment)
    assert snapshot(out) == before


# -- damaged studies, met by econet analyze -----------------------------------------------------
@pytest.fixture(scope="module")
def study(tmp_path_factory):
    out = tmp_path_factory.mktemp("study")
    config = Config().replace(**{"evolution.generations": 2, "evolution.population": 4,
                                 "evolution.parents": 2, "evolution.trials": 2,
                                 "evolution.cycles": 5})
    run_study(StudySpec(config, 1, 1), out, progress=False)
    return out


def _edit_study_json(**changes):
    def edit(out: Path) -> None:
        data = json.loads((out / "study.json").read_text())
        data.update(changes)
        (out / "study.json").write_text(json.dumps(data))
    return edit


def _replace_by_folder(path: Path) -> None:
    path.unlink()
    path.mkdir()


def _spoil_first_row(path: Path) -> None:
    lines = path.read_bytes().splitlines(keepends=True)
    lines[1] = b"x" + lines[1][1:]
    path.write_bytes(b"".join(lines))


RUN = Path("normal/run-01")
BAD_STUDIES = {
    "runs-abc": (_edit_study_json(runs="abc"), "runs must be a whole number of at least 1"),
    "seed-null": (_edit_study_json(seed=None), "seed must be a whole number of at least 0"),
    "variants-list": (_edit_study_json(variants=[1]), "variants must be a JSON object"),
    "study-json-list": (lambda out: (out / "study.json").write_text("[1]"),
                        "study.json is damaged (not a JSON object)"),
    "study-json-torn": (lambda out: (out / "study.json").write_text('{"runs'),
                        "study.json is damaged (empty, torn or not JSON"),
    "metrics-not-a-number": (lambda out: _spoil_first_row(out / RUN / "metrics.csv"),
                             "metrics.csv is damaged: line 2"),
    "npy-missing": (lambda out: (out / RUN / "genomes.npy").unlink(), "genomes.npy is missing"),
    "npy-truncated": (lambda out: os.truncate(out / RUN / "fitness.npy", 100),
                      "fitness.npy is truncated or not a NumPy array file"),
    "npy-text": (lambda out: (out / RUN / "fitness.npy").write_text("1 2 3\n"),
                 "fitness.npy is truncated or not a NumPy array file"),
    "npy-unreadable": (lambda out: _replace_by_folder(out / RUN / "best_genomes.npy"),
                       "cannot read"),
    "behaviour-not-a-number": (lambda out: _spoil_first_row(out / RUN / "behaviour.csv"),
                               "behaviour.csv is damaged: line 2"),
}


@pytest.mark.parametrize("damage, fragment", BAD_STUDIES.values(), ids=BAD_STUDIES.keys())
def test_analyze_names_what_is_wrong_with_a_damaged_study(tmp_path, capsys, study, damage,
                                                           fragment):
    copy = tmp_path / "study"
    shutil.copytree(study, copy)
    damage(copy)
    refused(capsys, main(["analyze", str(copy)]), fragment)
    assert not (copy / "report.md").exists()


def test_a_metrics_row_cut_mid_line_is_an_unfinished_generation(tmp_path, study):
    copy = tmp_path / "study"
    shutil.copytree(study, copy)
    metrics = copy / RUN / "metrics.csv"
    metrics.write_bytes(metrics.read_bytes()[:-7])
    _, groups = load_study(copy)
    assert groups["base"]["normal"].done == [1]
    assert "run-01: 1 of 2 generations" in groups["base"]["normal"].problems


@pytest.fixture
def no_analysis(monkeypatch):
    """Fails the test if the analysis starts (refusals must come before it)."""
    monkeypatch.setattr(report_module, "lesion_study",
                        lambda *args: pytest.fail("the analysis started"))


@pytest.mark.parametrize("where, fragment", [
    (lambda d: ["--report", str(d / "a-file" / "report.md")], "a file has that name"),
    (lambda d: ["--figures", str(d / "a-file")], "a file has that name"),
    (lambda d: ["--report", str(d)], "it is a folder"),
], ids=["report-folder-a-file", "figures-folder-a-file", "report-a-folder"])
def test_an_unwritable_report_path_is_refused_before_the_analysis(tmp_path, capsys, study,
                                                                  no_analysis, where, fragment):
    (tmp_path / "a-file").write_text("in the way")
    refused(capsys, main(["analyze", str(study), *where(tmp_path)]), fragment)


# -- output folders: read-only, a file, occupied ------------------------------------------------
@contextmanager
def tmpfs(folder: Path, options: str):
    """A tmpfs mounted on folder (skips the test where this process may not mount one)."""
    folder.mkdir(exist_ok=True)
    if os.geteuid() != 0 or subprocess.run(["mount", "-t", "tmpfs", "-o", options, "tmpfs",
                                            str(folder)], capture_output=True).returncode:
        pytest.skip("cannot mount a tmpfs here")
    try:
        yield folder
    finally:
        subprocess.run(["umount", "-l", str(folder)], check=True)


@pytest.fixture
def read_only(tmp_path):
    """A folder this process cannot write: by permissions, or for root a read-only tmpfs."""
    folder = tmp_path / "read-only"
    if os.geteuid() != 0:
        folder.mkdir()
        folder.chmod(0o555)
        yield folder
        folder.chmod(0o755)
    else:
        with tmpfs(folder, "ro,size=64k"):
            yield folder


def test_a_read_only_output_folder_is_refused(capsys, read_only):
    refused(capsys, main(["evolve", "--out", str(read_only / "results"), *TINY]),
            "cannot write to output folder")


def test_a_read_only_report_folder_is_refused(capsys, study, no_analysis, read_only):
    refused(capsys, main(["analyze", str(study), "--report", str(read_only / "report.md")]),
            "cannot write to output folder")


@pytest.mark.parametrize("out, fragment", [("a-file", "a file has that name"),
                                           ("a-file/results", "Not a directory")])
def test_an_output_folder_in_the_way_of_a_file_is_refused(tmp_path, capsys, out, fragment):
    (tmp_path / "a-file").write_text("in the way")
    refused(capsys, main(["evolve", "--out", str(tmp_path / out), *TINY]),
            f"cannot write to output folder {tmp_path / out}: {fragment}")


def test_a_second_writer_is_refused_and_a_killed_writer_resumes(tmp_path, capsys, reference):
    """Two evolves into one --out: the second is refused while the first runs; the first,
    killed at an arbitrary moment, leaves a folder the same command finishes identically."""
    out = tmp_path / "results"
    first = subprocess.Popen([sys.executable, "-m", "econet_ros", "evolve", "--out", str(out),
                              *LONG], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    try:
        while not (out / "run-01" / "run.json").exists():
            assert first.poll() is None, first.stderr.read()
            time.sleep(0.02)
        refused(capsys, main(["evolve", "--out", str(out), *LONG]),
                f"is being written by another econet process (pid {first.pid})")
        with pytest.raises(UsageError, match="being written by another econet process"):
            evolve_into(out / "run-01", RunData(reference["long"]).config, 1, 1)
        assert first.poll() is None
    finally:
        first.kill()
        first.wait()
    assert first.returncode == -signal.SIGKILL
    assert main(["evolve", "--out", str(out), *LONG]) == 0
    assert_same_run(out / "run-01", reference["long"])


def test_a_run_folder_is_locked_while_a_run_writes_it(tmp_path, reference):
    config = RunData(reference["tiny"]).config
    with locked(tmp_path):
        with pytest.raises(UsageError, match=f"pid {os.getpid()}"):
            evolve_into(tmp_path, config, 1, 1)
    assert not (tmp_path / "run.json").exists()


# -- kills in the middle of a write -------------------------------------------------------------
CHILD = """
import os, signal, sys
import econet_ros.run_folders as run_folders
def die():
    os.kill(os.getpid(), signal.SIGKILL)
{patch}
from econet_ros.cli import main
sys.exit(main(sys.argv[1:]))
"""
KILL_POINTS = {
    # the 9th row written: after generation 2's offspring, before its fitness
    "mid-arrays": """
write, calls = run_folders.RowWriter.write, []
def write_or_die(self, row, values):
    calls.append(row)
    if len(calls) == 9:
        die()
    write(self, row, values)
run_folders.RowWriter.write = write_or_die
""",
    "mid-metrics-row": """
append = run_folders.append_row
def append_or_die(path, values):
    if path.name == "metrics.csv" and values[0] == 2:
        with open(path, "a") as handle:
            handle.write("2,1,0.")
        die()
    append(path, values)
run_folders.append_row = append_or_die
""",
    "before-run-json-rename": """
replace = os.replace
def replace_or_die(source, target):
    if str(target).endswith("run.json"):
        die()
    replace(source, target)
os.replace = replace_or_die
""",
}


@pytest.mark.parametrize("patch", KILL_POINTS.values(), ids=KILL_POINTS.keys())
def test_a_kill_mid_write_then_a_resume_gives_the_undisturbed_files(tmp_path, reference, patch):
    out = tmp_path / "results"
    killed = subprocess.run([sys.executable, "-c", CHILD.format(patch=patch), "evolve",
                             "--out", str(out), *TINY], capture_output=True, text=True)
    assert killed.returncode == -signal.SIGKILL, killed.stderr
    assert main(["evolve", "--out", str(out), *TINY]) == 0
    assert_same_run(out / "run-01", reference["tiny"])
    assert not list((out / "run-01").glob(".*.tmp"))     # a killed rename's temporary file


# -- a full disk ----------------------------------------------------------------------------------
def fill(folder: Path) -> Path:
    """Write a file into folder until its filesystem is full."""
    filler = folder / "filler"
    with open(filler, "wb", buffering=0) as handle:
        try:
            while True:
                handle.write(b"\0" * 4096)
        except OSError as error:
            assert error.errno == errno.ENOSPC
    return filler


def test_a_full_disk_at_the_start_is_one_line_and_leaves_no_arrays(tmp_path, capsys):
    with tmpfs(tmp_path / "disk", "size=32k") as disk:     # the arrays need about 50 KB
        for _ in range(2):                      # a re-run says the same
            refused(capsys, main(["evolve", "--out", str(disk / "results"), *LONG]),
                    "disk full: cannot write")
            assert not list(disk.rglob("*.npy"))


def test_a_disk_filling_up_mid_run_keeps_every_finished_generation(tmp_path, capsys,
                                                                   monkeypatch, reference):
    with tmpfs(tmp_path / "disk", "size=1m") as disk:
        write = RunStore.write

        def write_then_fill(store, result, offspring):
            write(store, result, offspring)
            if result.generation == 0:
                fill(disk)

        monkeypatch.setattr(RunStore, "write", write_then_fill)
        out = disk / "results"
        refused(capsys, main(["evolve", "--out", str(out), *LONG]), "disk full: cannot write")
        done = RunData(out / "run-01").generations_done
        assert 0 < done < 150
        monkeypatch.undo()
        (disk / "filler").unlink()
        assert main(["evolve", "--out", str(out), *LONG]) == 0
        assert_same_run(out / "run-01", reference["long"])


def _no_space(*args):
    raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))


def test_a_simulated_full_disk_mid_run_keeps_every_finished_generation(tmp_path, capsys,
                                                                       monkeypatch, reference):
    """ENOSPC from the array writes of generation 2 (rows 1 + 3 x 2 were written before)."""
    pwrite, calls = os.pwrite, []

    def pwrite_until_full(fd, data, offset):
        calls.append(offset)
        return _no_space() if len(calls) > 7 else pwrite(fd, data, offset)

    monkeypatch.setattr(os, "pwrite", pwrite_until_full)
    out = tmp_path / "results"
    refused(capsys, main(["evolve", "--out", str(out), *TINY]), "disk full: cannot write")
    assert RunData(out / "run-01").generations_done == 2
    monkeypatch.undo()
    assert main(["evolve", "--out", str(out), *TINY]) == 0
    assert_same_run(out / "run-01", reference["tiny"])


def test_a_simulated_full_disk_at_the_start_leaves_no_arrays(tmp_path, capsys, monkeypatch,
                                                             reference):
    """The line says how much room the arrays need, in bytes for a small run (it said 0.0 MB)."""
    monkeypatch.setattr(os, "posix_fallocate", _no_space)
    out = tmp_path / "results"
    err = refused(capsys, main(["evolve", "--out", str(out), *TINY]), "disk full: cannot write")
    size = sum(np.load(array, mmap_mode="r").nbytes for array in reference["tiny"].glob("*.npy"))
    assert f"the run's arrays need {size:,} bytes" in err
    assert not list(out.rglob("*.npy"))
    assert run_folders.finished_generations(out / "run-01") == 0


def test_a_resume_onto_a_full_disk_is_one_line_and_changes_nothing(tmp_path, capsys,
                                                                  monkeypatch, reference):
    """A folder whose arrays still need their space reserved (made by an older version, as
    sparse files) met by a resume on a full disk (simulated)."""
    def two_generations_done(run: Path) -> None:
        metrics = run / "metrics.csv"
        metrics.write_bytes(b"".join(metrics.read_bytes().splitlines(keepends=True)[:3]))

    out = damaged_copy(reference["tiny"], tmp_path, two_generations_done)
    before = snapshot(out)
    monkeypatch.setattr(os, "posix_fallocate", _no_space)
    refused(capsys, main(["evolve", "--out", str(out), *TINY]), "disk full: cannot write")
    assert snapshot(out) == before
    monkeypatch.undo()
    assert main(["evolve", "--out", str(out), *TINY]) == 0
    assert_same_run(out / "run-01", reference["tiny"])

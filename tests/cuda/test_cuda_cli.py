"""--device cuda on the command line, under the simulator: the same result files as --device
cpu (evolve and study advancing a condition's runs together), and a one-line error where
numba-cuda or a GPU is missing."""
import sys
from pathlib import Path

import pytest
from cuda_helpers import needs_numba_cuda

import econet_ros
from econet_ros.cli import main
from econet_ros.config import Config
from econet_ros.run_folders import run_folder
from econet_ros.runs import evolve_into

TINY = ["--runs", "2", "--population", "4", "--parents", "2", "--trials", "3", "--cycles", "8",
        "--generations", "3", "--quiet"]
NOT_COMPARED = {"provenance.json", ".lock"}     # which code wrote a folder, and who held it


def files_of(folder: Path) -> dict[str, bytes]:
    return {str(path.relative_to(folder)): path.read_bytes()
            for path in sorted(folder.rglob("*")) if path.is_file()
            and path.name not in NOT_COMPARED}


@needs_numba_cuda
@pytest.mark.parametrize("condition", ["normal", "random"])
def test_evolve_on_cuda_writes_the_cpus_files(tmp_path, condition):
    for device in ("cpu", "cuda"):
        assert main(["evolve", "--out", str(tmp_path / device), "--condition", condition,
                     "--device", device, *TINY]) == 0
    on_cpu, on_cuda = files_of(tmp_path / "cpu"), files_of(tmp_path / "cuda")
    assert len(on_cpu) == 2 * 5 and on_cpu == on_cuda


STUDY = [*TINY[:TINY.index("--generations")], "--generations", "2", "--quiet", "--jobs", "1"]


@needs_numba_cuda
def test_study_on_cuda_advances_each_conditions_runs_together_to_the_cpus_files(tmp_path,
                                                                               monkeypatch):
    """Every launch tests both runs of a condition, each keeping its own behaviour record."""
    from econet_ros.cuda import CudaEvaluator
    launches, test_generations = [], CudaEvaluator.test_generations

    def counted(self, requests, record=False):
        launches.append((len(requests), record))
        return test_generations(self, requests, record)

    monkeypatch.setattr(CudaEvaluator, "test_generations", counted)
    for device in ("cpu", "cuda"):
        (tmp_path / device).mkdir()
        monkeypatch.chdir(tmp_path / device)        # the report names the folder: the same
        assert main(["study", "--out", "study", "--device", device, *STUDY]) == 0
    on_cpu, on_cuda = files_of(tmp_path / "cpu"), files_of(tmp_path / "cuda")
    assert "study/random/run-02/behaviour.csv" in on_cpu and on_cpu == on_cuda
    assert launches == [(2, "behaviour")] * 3 * 2
    # a lost behaviour.csv is made again by replay when the runs are opened together
    (tmp_path / "cuda" / "study" / "normal" / "run-01" / "behaviour.csv").unlink()
    assert main(["study", "--out", "study", "--device", "cuda", *STUDY]) == 0
    assert files_of(tmp_path / "cuda") == on_cuda


def one_line_error(capsys, arguments) -> str:
    assert main(arguments) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "Traceback" not in err
    return err


@pytest.mark.parametrize("command", [["evolve", "--out", "{out}"], ["study", "--out", "{out}"],
                                     ["sweep", "run", "{spec}", "--out", "{out}"]])
def test_without_numba_cuda_each_command_says_so_in_one_line(tmp_path, capsys, monkeypatch,
                                                             command):
    monkeypatch.setitem(sys.modules, "econet_ros.cuda_kernels", None)
    monkeypatch.delattr(econet_ros, "cuda_kernels", raising=False)
    spec = Path(__file__).parents[2] / "examples" / "sweeps" / "smoke.toml"
    arguments = [part.format(out=tmp_path / "out", spec=spec) for part in command]
    err = one_line_error(capsys, [*arguments, "--device", "cuda"])
    assert "needs numba-cuda" in err and 'pip install ".[cuda]"' in err
    assert not (tmp_path / "out" / "run-01").exists()


@needs_numba_cuda
def test_without_a_gpu_evolve_says_so_in_one_line(tmp_path, capsys, monkeypatch):
    from econet_ros import cuda_kernels
    monkeypatch.setattr(cuda_kernels.cuda, "is_available", lambda: False)
    err = one_line_error(capsys, ["evolve", "--out", str(tmp_path), "--device", "cuda", *TINY])
    assert "no CUDA GPU is usable here" in err and "--device cpu" in err


class Interrupted(Exception):
    pass


@needs_numba_cuda
def test_runs_resumed_at_different_generations_advance_together_to_the_cpus_files(tmp_path):
    """run-01 stopped after one generation, run-02 not started: evolve_together tests both in
    each launch, each at its own generation."""
    config = Config().replace(**{"evolution.population": 4, "evolution.parents": 2,
                                 "evolution.trials": 3, "evolution.cycles": 8,
                                 "evolution.generations": 3})

    def stop(result, offspring):
        raise Interrupted

    with pytest.raises(Interrupted):
        evolve_into(run_folder(tmp_path / "cuda", 1), config, 1, 1, on_generation=stop)
    assert main(["evolve", "--out", str(tmp_path / "cuda"), "--device", "cuda", *TINY]) == 0
    assert main(["evolve", "--out", str(tmp_path / "cpu"), "--device", "cpu", *TINY]) == 0
    assert files_of(tmp_path / "cpu") == files_of(tmp_path / "cuda")


@needs_numba_cuda
def test_a_controller_called_once_per_cycle_is_refused_in_one_line(tmp_path, capsys,
                                                                   monkeypatch):
    monkeypatch.syspath_prepend(str(Path(__file__).parents[1] / "plugin_example"))
    err = one_line_error(capsys, ["evolve", "--out", str(tmp_path), "--device", "cuda",
                                  "--controller", "econet_plugin_example:LinearController",
                                  *TINY])
    assert "LinearController has no compiled policy" in err and "--device cpu" in err
    assert not (tmp_path / "run-01").exists()

"""The CUDA engine against the CPU's, under the simulator, at tiny sizes: per-trial measures,
final state, traces and behaviour records equal; many populations in one launch equal each
alone, records included."""
import importlib.util
from pathlib import Path

import numpy as np
import pytest
from cuda_helpers import needs_numba_cuda

from econet_ros.config import Config
from econet_ros.cuda import CudaEngine, CudaEvaluator
from econet_ros.devices import DEVICES, batches_runs, make_evaluator
from econet_ros.evolution import (BatchEvaluator, InProcessEvaluator, genome_weights,
                                  initial_genomes)
from econet_ros.science.study import evolve_with_behaviour

pytestmark = needs_numba_cuda

TINY = {"evolution.population": 3, "evolution.parents": 1, "evolution.trials": 4,
        "evolution.cycles": 12}


def tiny(condition: str = "normal", **changes) -> Config:
    return Config().replace(**TINY, **{"evolution.condition": condition}, **changes)


def both(config: Config, generation: int = 0, record=False):
    """One generation tested on the CPU and on the (simulated) GPU."""
    cpu, gpu = InProcessEvaluator(config), CudaEvaluator(config)
    genomes = initial_genomes(config, cpu.n_weights, 7, 1)
    return (cpu, cpu.test_generation(genomes, 7, 1, generation, record),
            gpu, gpu.test_generation(genomes, 7, 1, generation, record))


@pytest.mark.parametrize("condition", ["normal", "three-layer", "random"])
def test_measures_and_final_state_equal_the_cpus(condition):
    cpu, on_cpu, gpu, on_gpu = both(tiny(condition))
    for name in ("fitness", "success", "latency", "separations"):
        assert np.array_equal(getattr(on_cpu.measures, name), getattr(on_gpu.measures, name))
    assert np.array_equal(on_cpu.parents, on_gpu.parents)
    for name in ("body", "shoulder", "elbow"):
        assert getattr(cpu.world, name).tobytes() == getattr(gpu.last, name)[0].tobytes()


def test_whole_degree_moves_and_cancelled_limits_equal_the_cpus():
    config = tiny(**{"model.angle_steps": "round", "model.joint_limit": "cancel"})
    cpu, on_cpu, gpu, on_gpu = both(config)
    assert np.array_equal(on_cpu.measures.fitness, on_gpu.measures.fitness)
    assert cpu.world.elbow.tobytes() == gpu.last.elbow[0].tobytes()


def test_traces_equal_the_cpus():
    _, on_cpu, _, on_gpu = both(tiny(), record=True)
    for name, value in on_cpu.trace._asdict().items():
        assert np.array_equal(value, getattr(on_gpu.trace, name)), name


def test_behaviour_records_equal_the_cpus():
    _, on_cpu, _, on_gpu = both(tiny(), record="behaviour")
    for name, value in on_cpu.trace._asdict().items():
        assert np.array_equal(value, getattr(on_gpu.trace, name)), name


def test_many_populations_in_one_launch_equal_each_alone():
    config = tiny()
    cpu = InProcessEvaluator(config)
    engine = CudaEngine(config)
    runs = [1, 2, 3]
    genomes = [initial_genomes(config, cpu.n_weights, 7, run) for run in runs]
    weights = [genome_weights(config, g) for g in genomes]
    setups = [cpu.trial_setups(7, run, 0) for run in runs]
    batch = engine.test_populations(weights, setups, [0, 0, 0])
    for k, run in enumerate(runs):
        alone = cpu.test_generation(genomes[k], 7, run, 0)
        assert np.array_equal(alone.measures.latency.ravel(), batch.measures[k].latency)
        assert cpu.world.shoulder.tobytes() == batch.shoulder[k].tobytes()


@pytest.mark.parametrize("record", [True, "behaviour"])
def test_many_populations_in_one_launch_keep_each_its_record(record):
    config = tiny()
    cpu, gpu = InProcessEvaluator(config), CudaEvaluator(config)
    requests = [(initial_genomes(config, cpu.n_weights, 7, run), 7, run, 0) for run in (1, 2, 3)]
    for request, together in zip(requests, gpu.test_generations(requests, record)):
        alone = cpu.test_generation(*request, record)
        for name, value in alone.trace._asdict().items():
            assert np.array_equal(value, getattr(together.trace, name)), name


@pytest.mark.parametrize("device", DEVICES)
def test_the_devices_table_says_whose_evaluator_advances_runs_together(device):
    assert batches_runs(device) == isinstance(make_evaluator(tiny(), device), BatchEvaluator)


def test_the_gpu_benchmark_runs_under_the_simulator(capsys):
    path = Path(__file__).parents[2] / "scripts" / "bench" / "bench_cuda.py"
    spec = importlib.util.spec_from_file_location("bench_cuda", path)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    assert bench.main(["--simulate", "--generations", "2"]) == 0
    out = capsys.readouterr().out
    assert "2/2 runs" in out and "econet-cycles/s" in out


def test_a_runs_behaviour_rows_equal_the_cpus(tmp_path):
    config = tiny(**{"evolution.generations": 2})
    for name, evaluator in (("cpu", InProcessEvaluator(config)), ("cuda", CudaEvaluator(config))):
        evolve_with_behaviour([(tmp_path / name, 1)], config, 5, evaluator)
    for name in ("behaviour.csv", "metrics.csv", "genomes.npy"):
        assert (tmp_path / "cpu" / name).read_bytes() == (tmp_path / "cuda" / name).read_bytes()

"""Trials on an NVIDIA GPU (``--device cuda``), with results identical to the CPU's.

``CudaEngine.test_populations`` tests many populations (of many runs) in one kernel launch,
one trial per GPU thread (econet_ros.cuda_kernels: the CPU kernels' own functions compiled by
numba-cuda); ``CudaEvaluator`` is the Evaluator of runs.evolve_into on it and, through
``test_generations``, the BatchEvaluator with which runs.evolve_together advances many runs in
one launch per generation. Trial starts, genome decoding, movement noise, selection and
mutation stay on the host, drawn from the same NumPy streams as on the CPU, so a run's folder
is the same file for file (docs/speed.md). numba-cuda is an extra (``pip install ".[cuda]"``);
econet_ros.devices imports this module only when a GPU is asked for, and this module says in
one line when it cannot be had.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np

from .config import Config
from .controllers import Controller
from .errors import DeviceError
from .evolution import (BatchEvaluator, GenerationRequest, GenerationResult, generation_setups,
                        genome_weights, noise_seed, score_generation)
from .plugins import make_controller
from .trials import (NO_BEHAVIOUR, NO_TRACE, BehaviourRecord, Policy, Record, Tally, Trace,
                     TrialMeasures)
from .world import Geometry, TrialSetup, WorldArrays


def load_kernels():
    """econet_ros.cuda_kernels, or DeviceError when numba-cuda or a GPU is missing."""
    try:
        from . import cuda_kernels
    except ImportError as error:
        raise DeviceError(f"--device cuda needs numba-cuda: pip install \".[cuda]\" in the "
                          f"checkout, or use --device cpu ({error})") from None
    if not cuda_kernels.cuda.is_available():
        raise DeviceError("--device cuda: no CUDA GPU is usable here (numba-cuda found no "
                          "device or driver); use --device cpu")
    return cuda_kernels


@dataclass
class TestedBatch:
    """What one launch found: per population, each trial's measures and final state."""

    measures: list[TrialMeasures]     # one per population, fields (n_envs,)
    body: np.ndarray                  # (populations, n_envs) final body axis, degrees
    shoulder: np.ndarray              # (populations, n_envs)
    elbow: np.ndarray                 # (populations, n_envs)
    records: list[Trace | BehaviourRecord | None]   # one per population (None: not asked for)


class CudaEngine:
    """Populations of one configuration tested on the GPU, n_envs = population x trials
    environments each, laid out as on the CPU (environment e = econet * trials + trial)."""

    def __init__(self, config: Config, controller: Controller | None = None):
        e = config.evolution
        self.kernels = load_kernels()
        self.config = config
        self.n_envs = e.population * e.trials
        self.controller = controller or make_controller(e.condition, self.n_envs, config)
        if self.controller.compiled(1) is None:
            raise DeviceError(f"{type(self.controller).__name__} has no compiled policy (it is "
                              "called once per cycle), so it cannot run on a GPU; use --device "
                              "cpu")
        self.geometry = Geometry.of(config.model)
        self.edges = [self._to_device(edge) for edge in self.geometry.window_edges()]

    def test_populations(self, weights: Sequence[np.ndarray], setups: Sequence[TrialSetup],
                         noise_seeds: Sequence[int], record: Record = False) -> TestedBatch:
        """Test population p's (econets, n_weights) ``weights[p]`` on its trial starts
        ``setups[p]`` (with movement noise ``noise_seeds[p]``), every population in one launch;
        ``record`` (trials.run_trials's) is kept for each population."""
        policies = [self._policy(w, seed) for w, seed in zip(weights, noise_seeds)]
        state = self._start_state(setups)
        cycles = self.config.evolution.cycles
        n = len(state.body)
        trace = Trace.empty(cycles, state.object_xy) if record is True else NO_TRACE
        behaviour = BehaviourRecord.empty(cycles, n) if record == "behaviour" else NO_BEHAVIOUR
        on_device = [self._tuple_to_device(value)
                     for value in (state, Tally.empty(n), trace, behaviour)]
        policy = self._joined(policies)
        kernels = self.kernels
        kernels.launch(kernels.kernel_for(policy, self.geometry), n, on_device[0], self.geometry,
                       policy, cycles, *on_device[1:], record is True, record == "behaviour")
        shape = (len(weights), self.n_envs)
        found = Tally(*(self._to_host(a).reshape(shape) for a in on_device[1]))
        final = [self._to_host(getattr(on_device[0], name)).reshape(shape)
                 for name in ("body", "shoulder", "elbow")]
        kept = on_device[2] if record is True else on_device[3] if record else None
        return TestedBatch([TrialMeasures.from_tally(Tally(*(a[p] for a in found)))
                            for p in range(len(weights))], *final,
                           self._records(kept, len(weights)))

    def _records(self, on_device, populations: int) -> list[Trace | BehaviourRecord | None]:
        """Each population's part of a launch's record (None each when none was kept)."""
        if on_device is None:
            return [None] * populations
        joined = type(on_device)(*(self._to_host(a) for a in on_device))
        return [joined.part(slice(p * self.n_envs, (p + 1) * self.n_envs))
                for p in range(populations)]

    def _policy(self, weights: np.ndarray, seed: int) -> Policy:
        """A population's policy as trials.run_trials runs it (host arrays)."""
        self.controller.load(weights, seed)
        return Policy.of(self.controller.compiled(self.config.evolution.cycles))

    def _joined(self, policies: list[Policy]) -> Policy:
        """One policy for all populations side by side, on the device."""
        first = policies[0]
        table = (np.concatenate([p.motor_table for p in policies], axis=1) if first.use_table
                 else first.motor_table)
        weights = np.concatenate([p.weights for p in policies])
        return first._replace(weights=self._to_device(weights),
                              layers=self._to_device(first.layers),
                              motor_table=self._to_device(np.ascontiguousarray(table)))

    def _start_state(self, setups: Sequence[TrialSetup]) -> WorldArrays:
        """The world's arrays at the trials' start, all populations side by side."""
        for setup in setups:
            if len(setup) != self.n_envs:
                raise ValueError(f"expected {self.n_envs} trial starts, got {len(setup)}")
        return WorldArrays.start(TrialSetup.joined(setups), self.config.model, self.edges)

    def _tuple_to_device(self, arrays):
        return type(arrays)(*(self._to_device(a) for a in arrays))

    def _to_device(self, array):
        """``array`` in device memory. Under numba's CUDA simulator the kernel is Python calling
        CPU compilations, which take NumPy arrays: there the host array itself."""
        if self.kernels.SIMULATED or not isinstance(array, np.ndarray):
            return array
        return self.kernels.cuda.to_device(np.ascontiguousarray(array))

    @staticmethod
    def _to_host(array) -> np.ndarray:
        return array if isinstance(array, np.ndarray) else array.copy_to_host()


class CudaEvaluator(BatchEvaluator):
    """The Evaluator of runs.evolve_into on the GPU (each generation one launch), and a
    BatchEvaluator, whose ``test_generations`` tests many runs' generations in one launch
    (runs.evolve_together); trial starts, decoding and noise as InProcessEvaluator draws them."""

    def __init__(self, config: Config, controller: Controller | None = None):
        self.config = config
        self.engine = CudaEngine(config, controller)
        self.last: TestedBatch | None = None      # the last generation's launch, for tests

    @property
    def n_weights(self) -> int:
        return self.engine.controller.n_params

    def trial_setups(self, seed: int, run: int, generation: int) -> TrialSetup:
        return generation_setups(self.config, seed, run, generation)

    def test_generation(self, genomes: np.ndarray, seed: int, run: int, generation: int,
                        record: Record = False) -> GenerationResult:
        return self.test_generations([(genomes, seed, run, generation)], record)[0]

    def test_generations(self, requests: Sequence[GenerationRequest],
                         record: Record = False) -> list[GenerationResult]:
        """Every request's generation in one launch, each result with its own record."""
        self.last = self.engine.test_populations(
            [genome_weights(self.config, genomes) for genomes, *_ in requests],
            [self.trial_setups(seed, run, generation) for _, seed, run, generation in requests],
            [noise_seed(seed, run, generation) for _, seed, run, generation in requests], record)
        results = [score_generation(self.config, generation, genomes, measures)
                   for (genomes, _, _, generation), measures in zip(requests,
                                                                    self.last.measures)]
        for result, kept in zip(results, self.last.records):
            result.trace = kept
        return results

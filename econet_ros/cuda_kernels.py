"""The trial kernel for NVIDIA GPUs: one thread runs one trial, through the CPU kernels' own
function (trials.run_block_trials: move, sense, the network, the contact tally, the trace and
behaviour records), which numba-cuda compiles for the GPU, so there is no second copy of the
physics. Imported only by econet_ros.cuda, and only when a GPU is asked for.

Bit for bit as on the CPU: NVVM contracts a * b + c into one fused multiply-add by default,
which rounds once where the CPU code rounds twice, and the results drift. numba-cuda 0.30.4 has
no switch for it, so the kernel is compiled with NVVM's ``-fma=0`` (``without_contraction``)
and without link-time optimisation (with LTO, nvJitLink generates the code and contracts on its
own): the PTX then has exactly the fused multiply-adds the code asks for (elementary._fma), and
IEEE division and square root. tests/cuda/test_cuda_ptx.py counts them.

Under numba's CUDA simulator (NUMBA_ENABLE_CUDASIM=1, the tests) the kernel's own lines run as
Python, one thread at a time, and the functions it calls run as their CPU compilations.
"""
from __future__ import annotations

import functools
from contextlib import contextmanager, nullcontext
from typing import Iterator

import numpy as np
from numba import typeof

from .config import Config
from .plugins import make_controller
from .trials import NO_BEHAVIOUR, NO_TRACE, Policy, Tally, run_block_trials
from .world import N_MOTOR, Geometry, WorldArrays

if not hasattr(np, "row_stack"):       # numba-cuda 0.30.4 names it at import; NumPy 2.5 has not
    np.row_stack = np.vstack

from numba import cuda                  # noqa: E402 - after the alias above
from numba.cuda.core import config      # noqa: E402

THREADS_PER_BLOCK = 128
SIMULATED = bool(config.ENABLE_CUDASIM)     # NUMBA_ENABLE_CUDASIM=1 when numba.cuda was imported
JIT_OPTIONS = {} if SIMULATED else {"lto": False}      # the simulator links nothing


@contextmanager
def without_contraction() -> Iterator[None]:
    """Compile with NVVM's -fma=0 while inside (a kernel compiles at its first launch)."""
    if SIMULATED:                       # nothing is compiled
        yield
        return
    from numba.cuda.cudadrv import nvvm
    compile_ir = nvvm.compile_ir

    def strict(llvmir, **options):
        if not options.get("fastmath"):
            options["fma"] = False
        return compile_ir(llvmir, **options)

    nvvm.compile_ir = strict
    try:
        yield
    finally:
        nvvm.compile_ir = compile_ir


@functools.cache
def trial_kernel(rows: int, n_inputs: int):
    """The kernel for activation buffers of ``rows`` rows (inputs, hidden units, outputs; at
    least the ``n_inputs`` senses): thread i runs environment i's whole trial, with the
    network ``i // policy.block``, and counts its fitness, latency and separations into
    element i of ``tally`` (a trials.Tally)."""

    @cuda.jit(**JIT_OPTIONS)
    def run_trials(world, geo, policy, cycles, tally, trace, behaviour, record_trace,
                   record_behaviour):
        i = cuda.grid(1)
        if i >= world.body.shape[0]:
            return
        buffer = cuda.local.array((rows, 1), np.float64)
        total = cuda.local.array(1, np.float64)
        senses = cuda.local.array(n_inputs, np.float64)
        motor = cuda.local.array(N_MOTOR, np.float64)
        last_angles = cuda.local.array((1, 3), np.float64)
        last_gap = cuda.local.array(1, np.float64)
        touched = cuda.local.array(1, np.bool_)
        for j in range(rows):
            buffer[j, 0] = 0.0
        for u in range(N_MOTOR):
            motor[u] = 0.0
        for j in range(3):
            last_angles[0, j] = 0.0
        last_gap[0], touched[0] = 0.0, False
        run_block_trials(i, i // policy.block, world, geo, policy, cycles, buffer, total, senses,
                         motor, last_angles, last_gap, touched, tally, trace, behaviour,
                         record_trace, record_behaviour)

    return run_trials


def kernel_for(policy: Policy, geometry: Geometry):
    """The trial kernel for a policy's activation buffer (its network's; the senses alone for a
    motor table) and the geometry's senses."""
    return trial_kernel(max(policy.buffer_size, geometry.n_inputs), geometry.n_inputs)


def launch(kernel, n_envs: int, *args) -> None:
    """Run ``kernel`` over n_envs threads, compiled without contraction."""
    blocks = (n_envs + THREADS_PER_BLOCK - 1) // THREADS_PER_BLOCK
    with without_contraction():
        kernel[blocks, THREADS_PER_BLOCK](*args)



def trial_kernel_ptx(config: Config, cc: tuple[int, int] = (9, 0), contract: bool = False) -> str:
    """The PTX of the trial kernel for ``config``'s network on compute capability ``cc``, as
    ``launch`` compiles it (``contract``: with NVVM's default contraction instead). Needs NVVM
    (the nvidia-nvvm and nvidia-cuda-nvrtc wheels, or a CUDA toolkit), not a GPU."""
    n = config.evolution.population * config.evolution.trials
    controller = make_controller(config.evolution.condition, n, config)
    policy = Policy.of(controller.compiled(config.evolution.cycles))
    geometry = Geometry.of(config.model)
    state = np.zeros(n)
    world = WorldArrays(state, state, state, state, np.zeros((n, 2)), *geometry.window_edges())
    args = (world, geometry, policy, config.evolution.cycles, Tally.empty(n), NO_TRACE, NO_BEHAVIOUR, False, False)
    with nullcontext() if contract else without_contraction():
        ptx, _ = cuda.compile_ptx(kernel_for(policy, geometry).py_func,
                                  tuple(typeof(a) for a in args), cc=cc)
    return ptx

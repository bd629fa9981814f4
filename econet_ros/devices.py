"""Where a command tests its populations (``--device``): the table of devices and the one
factory every command, the study and the sweep's tasks use; whether a device's evaluator
advances a configuration's runs together (the study hands it a condition's runs at once).

The CPU evaluator is this process's (evolution.InProcessEvaluator); a GPU's lives in
econet_ros.cuda, which is imported only when a GPU is asked for, so that CPU users never load
the CUDA back-end. Asking for one that cannot be had is a one-line DeviceError (cuda.py says
why: numba-cuda missing, or no usable GPU).
"""
from __future__ import annotations

from typing import NamedTuple

from .config import Config
from .controllers import Controller
from .evolution import Evaluator, InProcessEvaluator


class Device(NamedTuple):
    """What the commands need to know of a device before any evaluator exists."""

    gpus_per_run: float     # the share of a GPU a sweep's Ray task asks for (8 runs share one)
    batches_runs: bool      # its evaluator tests many runs' generations in one call


DEVICES = {"cpu": Device(gpus_per_run=0.0, batches_runs=False),
           "cuda": Device(gpus_per_run=0.125, batches_runs=True)}


def make_evaluator(config: Config, device: str = "cpu",
                   controller: Controller | None = None) -> Evaluator:
    """The evaluator that tests populations on ``device`` (one of DEVICES)."""
    if device == "cuda":
        from .cuda import CudaEvaluator
        return CudaEvaluator(config, controller)
    return InProcessEvaluator(config, controller)


def require_device(device: str) -> None:
    """DeviceError now, in one line, when ``device`` cannot be used here (before a command
    that hands the work to other processes starts any)."""
    if device == "cuda":
        from .cuda import load_kernels
        load_kernels()


def gpus_per_run(device: str) -> float:
    """The share of a GPU a Ray task evolving one run asks for on ``device``."""
    return DEVICES[device].gpus_per_run


def batches_runs(device: str) -> bool:
    """Whether ``device``'s evaluator tests many runs' generations at once (a BatchEvaluator),
    so that a command hands it all runs of one configuration together (runs.evolve_runs)
    rather than one run to each worker."""
    return DEVICES[device].batches_runs

"""Compile every kernel of the package into the numba cache, once.

So that the first `econet evolve`, the first node and the first benchmark after `scripts/setup`
run as fast as later ones:

    . scripts/env.sh && python -m econet_ros.kernels            # compile (about 2 minutes)
    . scripts/env.sh && python -m econet_ros.kernels --signatures FILE
                                                   # also write every compiled signature (tests)

numba compiles a kernel for each combination of argument types it is called with, so this runs
every path a command takes (evolution under each condition, with and without traces, the
study's behaviour rows, the per-cycle API the nodes and the Gymnasium env call) at a tiny size:
the types, not the sizes, decide what is compiled. The modules with kernels are listed in
econet_ros.KERNEL_MODULES, beside the import-time code that keys the cache folder by their
content. scripts/setup runs this when the cache for the current sources is missing and leaves
a stamp beside it; tests/core/test_compile_kernels.py checks that real commands compile nothing
it left out.
"""
from __future__ import annotations

import argparse
import importlib
import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from numba.core import config as numba_config

from . import KERNEL_MODULES
from .config import CONDITIONS, Config
from .evolution import InProcessEvaluator
from .nodes.lockstep_wire import SensorMessages
from .plugins import make_controller
from .runs import evolve_into
from .science.study import evolve_with_behaviour
from .world import World, sample_setups

TINY = {"evolution.population": 4, "evolution.parents": 2, "evolution.trials": 2,
        "evolution.cycles": 3, "evolution.generations": 2}


def warm_every_path() -> None:
    """Run each path that calls a kernel once, at a tiny size."""
    with tempfile.TemporaryDirectory(prefix="econet-compile-") as folder:
        for condition in CONDITIONS:
            config = Config().replace(**TINY, **{"evolution.condition": condition})
            evaluator = InProcessEvaluator(config)
            evolve_into(Path(folder) / condition / "run-01", config, 1, 1, evaluator)
            evolve_with_behaviour([(Path(folder) / condition / "study-01", 1)], config, 1,
                                  evaluator)
            warm_per_cycle(config)


def warm_per_cycle(config: Config, n_envs: int = 4) -> None:
    """The per-cycle API, as the world and controller nodes and the Gymnasium env call it, and
    the nodes' message writers (lockstep_wire)."""
    rng = np.random.default_rng(0)
    world = World(n_envs, config.model)
    obs = world.reset(sample_setups(rng, n_envs, config.model))
    controller = make_controller(config.evolution.condition, n_envs, config)
    controller.load(rng.uniform(-1, 1, (2, controller.n_params)))
    motor = controller.act(obs)
    if hasattr(controller, "forward"):
        controller.forward(obs.network_input())
    world.step(motor)
    wire = SensorMessages(n_envs, config.model.visual_units)
    wire.write(world, 0, False)
    wire.step(world, motor, 0, False)
    world.observe()
    world.restart(np.arange(1), sample_setups(rng, 1, config.model))
    world.arm_points()
    world.hand_object_distance()


def compiled_signatures() -> dict[str, list[str]]:
    """Every kernel of the package and the argument types it has been compiled for."""
    found = {}
    for module_name in KERNEL_MODULES:
        dotted = module_name.removesuffix(".py").replace("/", ".")
        module = importlib.import_module(f"econet_ros.{dotted}")
        for name, value in vars(module).items():
            if hasattr(value, "signatures") and hasattr(value, "py_func"):
                found[f"{module.__name__}.{name}"] = sorted(str(s) for s in value.signatures)
    return found


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--signatures", type=Path,
                        help="write the compiled signatures of every kernel to this JSON file")
    args = parser.parse_args()
    start = time.perf_counter()
    warm_every_path()
    if args.signatures:
        args.signatures.write_text(json.dumps(compiled_signatures(), indent=1))
    print(f"kernels compiled into {numba_config.CACHE_DIR} in "
          f"{time.perf_counter() - start:.0f} s (econet_ros {Path(__file__).parent})")
    return 0


if __name__ == "__main__":
    sys.exit(main())

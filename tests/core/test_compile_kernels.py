"""econet_ros.kernels, which scripts/setup runs so that no user pays for compiling, must
compile every kernel signature that real commands use: a study (evolution under every condition,
behaviour rows, the lesion, the optimizer comparison, the analysis), `econet evaluate`
(recording a bag) with every controller, the Gymnasium env and the world node's message writer.
Each side runs in its own process and reports the signatures its kernels hold, which numba
fills whether it compiles or loads from the cache (warm after scripts/setup)."""
import json
import subprocess
import sys
from pathlib import Path



ROOT = Path(__file__).resolve().parents[2]

REAL_COMMANDS = """
import json, sys
from econet_ros.cli.main import main
out = sys.argv[1]
tiny = ["--population", "10", "--parents", "2", "--trials", "2", "--cycles", "5",
        "--generations", "3"]
assert main(["study", "--out", out + "/study", "--runs", "1", "--jobs", "1", "--quiet",
             "--optimizers", *tiny]) == 0
for controller in ("normal", "three-layer", "random", "reacher"):
    assert main(["evaluate", "--controller", controller, "--trials", "3", "--cycles", "5",
                 "--record", out + "/bag-" + controller]) == 0
import gymnasium, econet_ros.gym
env = gymnasium.make("econet_ros/Reach-v0")
env.reset(seed=0)
env.step(env.action_space.sample())
import numpy as np
from econet_ros.config import Config
from econet_ros.nodes.lockstep_wire import SensorMessages
from econet_ros.world import World, sample_setups
model = Config().model
world, wire = World(3, model), SensorMessages(3, model.visual_units)
world.reset(sample_setups(np.random.default_rng(0), 3, model))
wire.write(world, 0, False)
wire.step(world, np.full((3, 5), 0.5), 0, False)
from econet_ros.kernels import compiled_signatures
print(json.dumps(compiled_signatures()))
"""


def signatures_of(args: list[str]) -> dict:
    result = subprocess.run([sys.executable, *args], capture_output=True, text=True, check=True,
                            cwd=ROOT)
    return json.loads(result.stdout.strip().splitlines()[-1])


def test_real_commands_compile_nothing_the_warm_up_leaves_out(tmp_path):
    warm_file = tmp_path / "warm.json"
    subprocess.run([sys.executable, "-m", "econet_ros.kernels", "--signatures", str(warm_file)],
                   check=True, capture_output=True, cwd=ROOT)
    warm = json.loads(warm_file.read_text())
    used = signatures_of(["-c", REAL_COMMANDS, str(tmp_path)])
    assert used, "no kernel signatures seen"
    missing = {name: sorted(set(sigs) - set(warm.get(name, ()))) for name, sigs in used.items()}
    missing = {name: sigs for name, sigs in missing.items() if sigs}
    assert not missing, f"compiled by real commands but not by econet_ros.kernels: {missing}"

"""The core (everything outside econet_ros/nodes) must work on machines without ROS: importing
it, and running its command line, never loads rclpy or any ROS message package. And the layout's
rules: nothing in nodes/ imports the command line, the reference model stays independent of the
engine it checks, and the kernel cache key lists every module with compiled kernels."""
import pkgutil
import re
import subprocess
import sys
from pathlib import Path

import econet_ros

PACKAGE = Path(econet_ros.__file__).parent
# What the reference model (econet_ros/reference) may load of the package besides itself: the
# settings it reads, and the package's root and errors that come with them.
REFERENCE_MAY_LOAD = {"econet_ros", "econet_ros.config", "econet_ros.errors"}
ROS = ("rclpy", "econet_msgs", "sensor_msgs", "std_msgs", "visualization_msgs", "geometry_msgs",
       "rcl_interfaces")


def core_modules() -> list[str]:
    """Every module of the package and its subpackages, except the ROS adapters."""
    return sorted(m.name for m in pkgutil.walk_packages(econet_ros.__path__, "econet_ros.")
                  if not m.name.startswith("econet_ros.nodes") and m.name != "econet_ros.__main__")


def test_core_modules_load_no_ros():
    core = core_modules()
    assert {"econet_ros.world", "econet_ros.controllers", "econet_ros.trials",
            "econet_ros.science.measures", "econet_ros.science.claims",
            "econet_ros.recording.bags", "econet_ros.cli.main", "econet_ros.topics"} <= set(core)
    code = ("import sys\n"
            + "".join(f"import {name}\n" for name in core)
            + f"ros = sorted(m for m in sys.modules if m.split('.')[0] in {ROS!r})\n"
            + "print(','.join(ros))\n")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            check=True)
    assert result.stdout.strip() == "", f"ROS modules loaded by the core: {result.stdout}"


def test_only_nodes_import_ros_and_no_node_imports_the_command_line():
    pattern = re.compile(r"^\s*(?:from|import)\s+(" + "|".join(ROS) + r")\b", re.M)
    for path in PACKAGE.rglob("*.py"):
        text = path.read_text(encoding="utf-8")
        inside_nodes = "nodes" in path.relative_to(PACKAGE).parts
        if not inside_nodes:
            assert not pattern.search(text), f"{path} imports ROS outside nodes/"
        else:
            assert not re.search(r"^\s*from\s+\.\.cli\b|econet_ros\.cli\b", text, re.M), \
                f"{path} imports the command line"


def test_the_reference_model_loads_nothing_of_the_engine():
    reference = [name for name in core_modules() if name.startswith("econet_ros.reference.")]
    assert {"econet_ros.reference.model", "econet_ros.reference.evolution",
            "econet_ros.reference.partings"} <= set(reference)
    code = ("import sys\n"
            + "".join(f"import {name}\n" for name in reference)
            + "print(' '.join(m for m in sys.modules if m.startswith('econet_ros')))\n")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            check=True)
    loaded = {m for m in result.stdout.split() if not m.startswith("econet_ros.reference")}
    assert loaded <= REFERENCE_MAY_LOAD, \
        f"the reference model loads the engine: {sorted(loaded - REFERENCE_MAY_LOAD)}"


def test_cpu_users_never_load_the_cuda_back_end():
    """The command line, the study and the sweep reach devices only through econet_ros.devices,
    which imports econet_ros.cuda when a GPU is asked for."""
    code = ("import sys\n"
            "import econet_ros.cli.main, econet_ros.science.study, econet_ros.devices\n"
            "import econet_ros.science.sweeps.runner\n"
            "from econet_ros.cli.main import build_parser\n"
            "build_parser()\n"
            "print(' '.join(m for m in sys.modules\n"
            "               if m.startswith(('econet_ros.cuda', 'numba.cuda'))))\n")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            check=True)
    assert result.stdout.strip() == "", f"CPU users load: {result.stdout}"


def test_kernel_cache_key_lists_every_module_with_kernels():
    with_kernels = {str(p.relative_to(PACKAGE)) for p in PACKAGE.rglob("*.py")
                    if "@numba.njit" in p.read_text(encoding="utf-8")}
    assert with_kernels == set(econet_ros.KERNEL_MODULES)

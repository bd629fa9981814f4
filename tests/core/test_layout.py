"""The core (everything outside econet_ros/nodes) must work on machines without ROS: importing
it, and running its command line, never loads rclpy or any ROS message package. And the layout's
rules: nothing in nodes/ imports the command line, nothing outside the studies wing imports the
wing (the library finds its rules and verbs by name, plugins.py), the library names no study,
seed or cell of ours, the reference model stays independent of the engine it checks, CPU users
never load the CUDA back-end, and the kernel cache key lists every module with compiled
kernels."""
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


WING = PACKAGE / "studies"
IMPORTS_WING = re.compile(r"^\s*(?:from\s+(?:econet_ros\.studies|\.+studies)\b"
                          r"|import\s+econet_ros\.studies"
                          r"|from\s+(?:econet_ros|\.+)\s+import\s+[^\n]*\bstudies\b)", re.M)


def library_files() -> list[Path]:
    return [p for p in PACKAGE.rglob("*.py") if WING not in p.parents]


def test_nothing_outside_the_studies_wing_imports_it():
    assert (WING / "__init__.py").exists()
    for path in library_files():
        assert not IMPORTS_WING.search(path.read_text(encoding="utf-8")), \
            f"{path} imports the studies wing"


def test_the_wing_import_pattern_catches_every_spelling():
    for line in ("from econet_ros.studies import rules", "from ...studies.family import x",
                 "import econet_ros.studies.rules", "from .. import studies",
                 "from econet_ros import config, studies"):
        assert IMPORTS_WING.search(line), line
    assert not IMPORTS_WING.search("from ..science import study")


# our studies' seeds (9201-9210 the screen's, 9501- the check's), rule names and cells: they
# belong in the specs (examples/sweeps) and the wing, never in the library's code
STUDY_WORDS = re.compile(r"\b9[2-5]\d\d\b|['\"](?:e[1-4]-[a-z]+|confirmatory|regime|load-map|"
                         r"readings)['\"]|four-\d-\d-\d|three-\d+\b")


def test_the_library_names_no_study_seed_or_cell():
    for path in library_files():
        found = STUDY_WORDS.findall(path.read_text(encoding="utf-8"))
        assert not found, f"{path} names {found}"

"""econet_ros: the econet model of infant reaching (Schlesinger, Parisi & Langer, 2000) as a
ROS-free core (this package, science/, recording/, cli/) and ROS 2 nodes (econet_ros.nodes).
The layout and the data path: docs/architecture.md."""
import hashlib as _hashlib
import os as _os
from pathlib import Path as _Path

# One BLAS thread, unless set otherwise: the package's linear algebra is small (CMA-ES's 64 x 64
# covariance), and BLAS threads only contend with the compiled kernels' threads, which made
# CMA-ES's update ten times slower on a busy two-core machine. This takes effect only when
# econet_ros is imported before numpy (as by `econet` and `python -m econet_ros`).
_os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

# numba's cache=True revalidates a cached kernel only by the timestamp of the file that defines
# it, not of the files whose functions it inlines (world.py's physics and controllers.py's
# network run inside trials.py's whole-trial kernel), so after an edit or an update a stale
# kernel could run. Keying the cache folder by the content of every module with kernels makes
# any change start a fresh cache (tests/core/test_layout.py checks that this list names
# every module with a kernel; econet_ros.kernels compiles them all ahead of use). An explicit
# NUMBA_CACHE_DIR is respected.
KERNEL_MODULES = ("elementary.py", "world.py", "controllers.py", "trials.py",
                  "nodes/lockstep_wire.py")


def _kernel_cache_dir(package: _Path = _Path(__file__).parent) -> str:
    digest = _hashlib.sha256()
    for name in KERNEL_MODULES:
        digest.update((package / name).read_bytes())
    base = _os.environ.get("XDG_CACHE_HOME") or _os.path.join(_os.path.expanduser("~"), ".cache")
    return _os.path.join(base, "econet_ros", "numba-" + digest.hexdigest()[:16])


if not _os.environ.get("NUMBA_CACHE_DIR"):
    from numba.core import config as _numba_config

    _numba_config.CACHE_DIR = _kernel_cache_dir()

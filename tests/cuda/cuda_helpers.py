"""What the CUDA tests share."""
import importlib.util

import pytest

# numba-cuda's own package (numba ships an older numba.cuda of its own, which is not enough)
needs_numba_cuda = pytest.mark.skipif(importlib.util.find_spec("numba_cuda") is None,
                                      reason="numba-cuda is not installed (pip install .[cuda])")

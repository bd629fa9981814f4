"""The CUDA path's tests run everywhere, under numba's CUDA simulator: numba-cuda reads
NUMBA_ENABLE_CUDASIM when numba.cuda is first imported, so it is set here, before any test
imports it. The simulator runs the kernel's own lines as Python and the functions it calls
(sense, move, the network, the elementary functions) as their CPU compilations, so these tests
check the kernel's layout and bookkeeping; the GPU's arithmetic is checked by the PTX test
(test_cuda_ptx.py, where NVVM is installed) and by scripts/bench/bench_cuda.py on a GPU."""
import os

os.environ["NUMBA_ENABLE_CUDASIM"] = "1"

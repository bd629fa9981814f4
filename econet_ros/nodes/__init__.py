"""ROS 2 adapters around the ROS-free core: the world, controller and supervisor nodes.

All rclpy code of the project lives in this package; see docs/ros-graph.md for the graph.
"""

import os as _os

# In the graph, world and controller compute in turn (lockstep). OpenMP worker threads that
# spin-wait after a parallel kernel (libgomp's default) would eat the cores the other node is
# computing on; sleeping workers cost only a wake-up. Must be set before numba starts OpenMP.
_os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

"""The reaching task as Gymnasium environments (docs/gym.md): ``ReachEnv``, one trial, and
``ReachVectorEnv``, thousands of trials stepped in one call, both over the same World as the
rest of the package. Importing this package registers them as ``econet_ros/Reach-v0``:

    import gymnasium
    import econet_ros.gym
    env = gymnasium.make("econet_ros/Reach-v0")
    envs = gymnasium.make_vec("econet_ros/Reach-v0", num_envs=2000,
                              vectorization_mode="vector_entry_point")

or, without the import, ``gymnasium.make("econet_ros.gym:econet_ros/Reach-v0")``. (Gymnasium
1.x no longer reads plug-in entry points, so registering needs this import; importing
``econet_ros`` alone does not load Gymnasium.)
"""
import os as _os

# A vector step is one short parallel kernel (about 0.3 ms for 2000 environments); OpenMP
# workers that spin-wait after it (libgomp's default) made steps up to ten times slower on a
# busy machine, sleeping workers cost only a wake-up (docs/speed.md, "The Gymnasium vector environment"). As in
# econet_ros.nodes; it must be set before numba starts OpenMP.
_os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

from gymnasium.envs.registration import register, registry  # noqa: E402

from .reach import ReachEnv  # noqa: E402
from .vector import ReachVectorEnv  # noqa: E402

ENV_ID = "econet_ros/Reach-v0"

if ENV_ID not in registry:
    register(id=ENV_ID, entry_point="econet_ros.gym.reach:ReachEnv",
             vector_entry_point="econet_ros.gym.vector:ReachVectorEnv")

__all__ = ["ENV_ID", "ReachEnv", "ReachVectorEnv"]

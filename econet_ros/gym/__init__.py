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
from gymnasium.envs.registration import register, registry

from .reach import ReachEnv
from .vector import ReachVectorEnv

ENV_ID = "econet_ros/Reach-v0"

if ENV_ID not in registry:
    register(id=ENV_ID, entry_point="econet_ros.gym.reach:ReachEnv",
             vector_entry_point="econet_ros.gym.vector:ReachVectorEnv")

__all__ = ["ENV_ID", "ReachEnv", "ReachVectorEnv"]

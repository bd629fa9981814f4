"""Start the econet graph on a ROS 2 installation:

    ros2 launch econet_ros econet_graph.launch.py [generations:=10 population:=20 ...]

(world_node, controller_node and supervisor_node as three processes; the supervisor evolves a
population through the graph and writes its result folder to `out`.) Its arguments are the
supervisor's parameters, generated from its PARAMETERS table (econet_ros.config's evolution
settings and the supervisor's run parameters), so they cannot drift. The launch package is not
installable here; scripts/graph-demo does the same from a checkout.
"""
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

from econet_ros.nodes.supervisor_node import PARAMETERS

ARGS = {param.name: (str(param.default), param.help) for param in PARAMETERS}


def generate_launch_description():
    c = {name: LaunchConfiguration(name) for name in ARGS}
    return LaunchDescription([
        *[DeclareLaunchArgument(name, default_value=default, description=text)
          for name, (default, text) in ARGS.items()],
        Node(package="econet_ros", executable="world_node", name="world",
             parameters=[{"config": c["config"]}]),
        Node(package="econet_ros", executable="controller_node", name="controller",
             parameters=[{"controller": c["condition"], "config": c["config"]}]),
        Node(package="econet_ros", executable="supervisor_node", name="supervisor",
             parameters=[{name: c[name] for name in ARGS}], output="screen"),
    ])

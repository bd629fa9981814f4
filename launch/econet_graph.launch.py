"""Start the econet graph on a ROS 2 installation:

    ros2 launch econet_ros econet_graph.launch.py [generations:=10 population:=20 ...]

(world_node, controller_node and supervisor_node as three processes; the supervisor evolves a
population through the graph and writes its result folder to `out`.) The launch package is not
installable here; scripts/graph-demo does the same from a checkout.
"""
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

ARGS = {
    "condition": ("normal", "network of the controller and condition of the run"),
    "config": ("", "JSON config file shared by all three nodes"),
    "out": ("results/graph", "result folder"),
    "generations": ("200", "generations per run"),
    "population": ("100", "econets per generation"),
    "parents": ("20", "econets selected to reproduce"),
    "trials": ("20", "trials per econet"),
    "cycles": ("100", "cycles per trial"),
    "seed": ("1", "base random seed"),
    "runs": ("1", "independent runs"),
}


def generate_launch_description():
    c = {name: LaunchConfiguration(name) for name in ARGS}
    return LaunchDescription([
        *[DeclareLaunchArgument(name, default_value=default, description=text)
          for name, (default, text) in ARGS.items()],
        Node(package="econet_ros", executable="world_node", name="world",
             parameters=[{"config": c["config"]}]),
        Node(package="econet_ros", executable="controller_node", name="controller",
             parameters=[{"network": c["condition"], "config": c["config"]}]),
        Node(package="econet_ros", executable="supervisor_node", name="supervisor",
             parameters=[{name: c[name] for name in ARGS}], output="screen"),
    ])

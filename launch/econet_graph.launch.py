"""Start the econet graph on a ROS 2 installation:

    ros2 launch econet_ros econet_graph.launch.py [generations:=10 population:=20 ...]
    ros2 launch econet_ros econet_graph.launch.py composed:=true [generations:=10 ...]

(world_node, controller_node and supervisor_node as three processes, or with composed:=true as
nodes of one process, graph_node; the supervisor evolves a population through the graph and
writes its result folder to `out`.) Its arguments are the supervisor's parameters, generated
from its PARAMETERS table (econet_ros.config's evolution settings and the supervisor's run
parameters), so they cannot drift; the controller node gets the supervisor's config, condition
and controller and decides from them as the supervisor does (`controller:=random` runs random
movement in both forms). The composed process gets each node's parameters in that
node's own section of its command line (graph_node), not as a parameters file, which would give
them to all three. The launch package is not installable here: tests/nodes/test_graph_commands.py
builds this description with stand-ins for it and runs what it would start; scripts/graph-demo
[--composed] does the same from a checkout.
"""
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.conditions import IfCondition, UnlessCondition
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

from econet_ros.nodes.supervisor_node import PARAMETERS

ARGS = {param.name: (str(param.default), param.help) for param in PARAMETERS}
STRINGS = {param.name for param in PARAMETERS if param.type is str}


def section(node: str, values: dict) -> list:
    """graph_node's section of one node: NODE --ros-args -p name:=value ... (strings quoted,
    so that an empty or numeric-looking one stays a string)."""
    args = [node, "--ros-args"]
    for name, value in values.items():
        args += ["-p", [f"{name}:='", value, "'"] if name in STRINGS
                 else [f"{name}:=", value]]
    return args


def generate_launch_description():
    c = {name: LaunchConfiguration(name) for name in ARGS}
    apart, composed = (UnlessCondition(LaunchConfiguration("composed")),
                       IfCondition(LaunchConfiguration("composed")))
    # the controller node decides as the supervisor does (plugins.chosen_controller), from the
    # same values: controller:=NAME, else the condition's network
    controller = {name: c[name] for name in ("config", "condition", "controller")}
    return LaunchDescription([
        DeclareLaunchArgument("composed", default_value="false",
                              description="world, controller and supervisor in one process"),
        *[DeclareLaunchArgument(name, default_value=default, description=text)
          for name, (default, text) in ARGS.items()],
        Node(package="econet_ros", executable="world_node", name="world",
             parameters=[{"config": c["config"]}], condition=apart),
        Node(package="econet_ros", executable="controller_node", name="controller",
             parameters=[controller], condition=apart),
        Node(package="econet_ros", executable="supervisor_node", name="supervisor",
             parameters=[{name: c[name] for name in ARGS}], output="screen", condition=apart),
        Node(package="econet_ros", executable="graph_node", output="screen",
             arguments=[*section("world", {"config": c["config"]}),
                        *section("controller", controller),
                        *section("supervisor", c)], condition=composed),
    ])

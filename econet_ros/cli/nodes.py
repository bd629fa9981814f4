"""The nodes' console scripts (``ros2 run econet_ros world_node``, ..., and
``graph_node``, the graph composed in one process): each starts its node,
or, where ROS 2 or a node's optional dependency is not installed (a core installed by pip), says
in one line what is missing instead of a traceback."""
from __future__ import annotations

import importlib
import importlib.util
import sys

from .main import missing_dependency


def run(node: str) -> int:
    """Start ``econet_ros.nodes.<node>`` with the command line's arguments."""
    try:
        if importlib.util.find_spec("rclpy") is None:
            raise ModuleNotFoundError("No module named 'rclpy'", name="rclpy")
        module = importlib.import_module(f"econet_ros.nodes.{node}")
    except ModuleNotFoundError as error:
        print(f"{node}: error: {missing_dependency(error, node)}", file=sys.stderr)
        return 2
    return module.main()


def world_node() -> int:
    return run("world_node")


def controller_node() -> int:
    return run("controller_node")


def supervisor_node() -> int:
    return run("supervisor_node")


def recorder_node() -> int:
    return run("recorder_node")


def viewer_node() -> int:
    return run("viewer_node")


def graph_node() -> int:
    return run("graph_node")

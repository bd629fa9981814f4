"""The graph composed in one process: world, controller and supervisor (and the recorder and the
viewer when named) as nodes of one process that share one executor, started by one command:

    graph_node [--ros-args ARGS] [world|controller|supervisor|recorder|viewer [--ros-args ARGS]]...

e.g.  graph_node --ros-args -r __ns:=/lab1 -- controller --ros-args -p controller:=random \\
        supervisor --ros-args -p generations:=10 -p out:=results/graph

Each node's section takes exactly the arguments that node takes when it runs alone, and gives
them to that node only (rclpy's cli_args: parameters, remappings, a namespace, a params file);
the arguments before the first node name go to every node, as a process's own arguments do in
a component container (a namespace for the whole graph, `-p config:=FILE`, a --params-file with
one section per node, a log level). Topics, services and parameters are those of the nodes
apart, so an outside node (a monitor, a recorder, another controller, ros2 topic echo, ros2
param get /world n_envs) sees and uses them as it would with three processes; the messages
still go through the middleware. The graph runs one controller (plugins.chosen_controller): the
one named with controller:= in the controller's or the supervisor's section (naming two is an
error), else the supervisor's condition's network; the example runs random movement and records
it in run-01/controller.json, as `econet evolve --controller random` does.

One executor in one thread: the supervisor evolves as it does alone, and while it waits for a
service reply or for touch it spins that executor, which runs the world's and controller's
callbacks in between, so no wait can block the callback it waits for. The process ends when the
evolution ends (with the supervisor's exit status), or on SIGINT or SIGTERM. A named recorder
records from before the first generation and closes its bag at the end.
"""
from __future__ import annotations

import importlib
import sys
from typing import Callable

from rclpy.node import Node

from ..errors import EconetError, UsageError
from ..plugins import EXTERNAL
from .runner import check_stop, print_help, run_nodes, wants_help

NODES = ("world", "controller", "recorder", "viewer", "supervisor")     # in the order built
ALWAYS = ("world", "controller", "supervisor")
# rcl's arguments that take a value (which may look like a node's name, e.g. a params file)
_TAKES_VALUE = {"-p", "--param", "-r", "--remap", "--params-file", "--log-level",
                "--log-file-name", "--log-config-file", "-e", "--enclave"}


def split_sections(args: list[str]) -> tuple[list[str], dict[str, list[str]]]:
    """(the arguments for every node, {node: its own arguments}) of the command line after the
    program's name."""
    shared: list[str] = []
    sections: dict[str, list[str]] = {}
    current, after_flag = shared, False
    for arg in args:
        if arg in NODES and not after_flag:
            if arg in sections:
                raise UsageError(f"{arg} is named twice")
            current = sections[arg] = []
        else:
            current.append(arg)
        after_flag = arg in _TAKES_VALUE
    return shared, sections


def check_sections(shared: list[str], sections: dict[str, list[str]]) -> None:
    """UsageError unless each section is empty or starts with --ros-args (rclpy would ignore
    anything else without a word)."""
    for name, given in (("the graph", shared), *sections.items()):
        if given and given[0] != "--ros-args":
            raise UsageError(f"{name}: expected --ros-args before {given[0]!r} (see --help)")


def node_class(name: str) -> type[Node]:
    """WorldNode, ControllerNode, ... (imported only when named: the viewer needs foxglove)."""
    try:
        module = importlib.import_module(f"{__package__}.{name}_node")
    except ModuleNotFoundError as error:
        raise UsageError(f"the {name} node needs the module {error.name}, which is not "
                         "installed") from None
    return getattr(module, f"{name.capitalize()}Node")


def makers(names: list[str], sections: dict[str, list[str]]) -> list[Callable[[], Node]]:
    """A maker per named node, each building its node from its own section. The graph runs
    one controller: a controller named in the controller's section counts as named to the
    supervisor, and the controller node then runs what the supervisor decided
    (plugins.chosen_controller)."""
    built: dict[str, Node] = {}

    def maker(name: str, cls: type[Node]) -> Callable[[], Node]:
        def make() -> Node:
            options = {"cli_args": sections.get(name, [])}
            if name == "supervisor":
                options["controller_section"] = built["controller"].named
            try:
                node = built[name] = cls(**options)
                if name == "supervisor" and node.controller != EXTERNAL:
                    built["controller"].follow(node.controller)
            except EconetError as error:        # say which node: they share the command line
                raise type(error)(f"{name}: {error}") from None
            return node
        return make
    return [maker(name, node_class(name)) for name in names]


def _run(nodes: list[Node], executor) -> int:
    """Wait until every node that can say so is ready (a recorder records), then evolve; the
    nodes that close something (a recorder's bag) close it whatever happens."""
    from .supervisor_node import SupervisorNode, evolve_with

    finished = False
    try:
        while not all(node.ready() for node in nodes if hasattr(node, "ready")):
            check_stop()
            executor.spin_once(timeout_sec=0.05)
        supervisor = next(node for node in nodes if isinstance(node, SupervisorNode))
        status = evolve_with(supervisor, executor)
        finished = True
        return status
    finally:
        for node in nodes:
            if hasattr(node, "close"):
                node.close(executor if finished else None)


def main(args: list[str] | None = None) -> int:
    args = sys.argv if args is None else args
    prog = "graph_node"
    try:
        shared, sections = split_sections(args[1:])
        for name, given in sections.items():
            if wants_help(given):
                return sys.modules[node_class(name).__module__].main([f"{name}_node", "--help"])
        if wants_help(shared):
            return print_help(f"{__doc__.strip()}\n\nEach node's parameters: graph_node NODE "
                              "--help (as scripts/node NODE --help).")
        check_sections(shared, sections)
        names = [name for name in NODES if name in ALWAYS or name in sections]
        graph = makers(names, sections)
    except UsageError as error:
        print(f"{prog}: error: {error}", file=sys.stderr)
        return 2
    return run_nodes(prog, [args[0], *shared], graph, _run)


if __name__ == "__main__":
    sys.exit(main())

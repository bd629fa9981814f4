"""Running a node (run_node), or several in one process on one executor (run_nodes, for
graph_node): its parameters declared from one table (with types, ranges and descriptions, as
turtlesim does), ``--help`` from the same table, the executor, and the one place where an
EconetError becomes one line on stderr (exit 2) and SIGINT or SIGTERM end quietly (exit 0).

Signals only raise a flag (rclpy's own handlers, which shut the context down at once, are not
installed): a callback that is publishing when the signal comes finishes, and the node stops
between callbacks, where every spin loop checks the flag (``serve``, ``check_stop``)."""
from __future__ import annotations

import os
import signal
import sys
import threading
from typing import Any, Callable, NamedTuple

import rclpy
from rcl_interfaces.msg import (FloatingPointRange, IntegerRange, ParameterDescriptor,
                                ParameterType)
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.signals import SignalHandlerOptions

from ..config import Config, Setting, checked_value, load_config
from ..errors import ConfigError, EconetError, options_as_parameters


class Param(NamedTuple):
    """A node parameter: its default (which fixes its type), what it means, and the values it
    may take (choices, or the closed range low..high)."""

    name: str
    default: Any
    help: str
    low: float | None = None
    high: float | None = None
    choices: tuple | None = None

    # what config.checked_value needs to check a value against this parameter
    @property
    def key(self) -> str:
        return self.name

    @property
    def type(self) -> type:
        return type(self.default)

    @classmethod
    def of_setting(cls, item: Setting) -> "Param":
        """A config field as a parameter of the same name."""
        source = "paper" if item.paper else "assumption"
        return cls(item.name, item.default, f"{item.help} ({source})", item.low, item.high,
                   item.choices)

    def allowed(self) -> str:
        """The values it may take, in words ('' if any value of its type)."""
        if self.choices:
            return f"one of {', '.join(map(str, self.choices))}"
        if self.low is not None and self.high is not None:
            return f"{self.low:g} to {self.high:g}"
        if self.low is not None:
            return f"at least {self.low:g}"
        return f"at most {self.high:g}" if self.high is not None else ""


_TYPES = {bool: ParameterType.PARAMETER_BOOL, int: ParameterType.PARAMETER_INTEGER,
          float: ParameterType.PARAMETER_DOUBLE, str: ParameterType.PARAMETER_STRING}
_TYPE_NAMES = {bool: "bool", int: "integer", float: "double", str: "string"}
_UNBOUNDED = {int: 2 ** 62, float: 1e308}


def descriptor(param: Param) -> ParameterDescriptor:
    """What `ros2 param describe` shows: type, description, range or choices."""
    described = ParameterDescriptor(description=param.help, type=_TYPES[param.type])
    if param.type in (int, float) and (param.low is not None or param.high is not None):
        big = _UNBOUNDED[param.type]
        low = param.type(param.low) if param.low is not None else -big
        high = param.type(param.high) if param.high is not None else big
        if param.type is int:
            described.integer_range = [IntegerRange(from_value=low, to_value=high, step=0)]
        else:
            described.floating_point_range = [FloatingPointRange(from_value=low, to_value=high,
                                                                 step=0.0)]
    if param.choices:
        described.additional_constraints = param.allowed()
    return described


def declare_parameters(node: Node, table: tuple[Param, ...]) -> dict[str, Any]:
    """Declare every parameter of the table; returns {name: value}. A value given as the user
    types it is checked here (an integer where a float is expected is accepted, as for the
    config), so that a bad one is one ConfigError instead of rclpy's traceback; a name the
    node does not have is one too."""
    # rclpy keeps the --ros-args / params-file values here; it has no public accessor.
    given = node._parameter_overrides
    values = {}
    for param in table:
        value = checked_value(param, given[param.name].value) if param.name in given \
            else param.default
        node.declare_parameter(param.name, value, descriptor(param), ignore_override=True)
        values[param.name] = value
    unknown = sorted(name for name in given if not node.has_parameter(name))
    if unknown:
        raise ConfigError(f"unknown parameter(s) {', '.join(unknown)} (see --help)")
    return values


def default_from(node: Node, values: dict[str, Any], defaults: dict[str, Any]) -> None:
    """Parameters the user did not give take these defaults instead of the table's (e.g. the
    settings of the `config` file); `ros2 param get` then shows what the node uses."""
    for name, value in defaults.items():
        if name not in node._parameter_overrides:
            values[name] = value
            node.set_parameters([Parameter(name, value=value)])


def node_config(path: str) -> Config:
    """The Config a node runs with: defaults, or the JSON file `path` (as `econet --config`)."""
    return load_config(path) if path else Config()


def usage(prog: str, doc: str, table: tuple[Param, ...]) -> str:
    """The --help text: what the node does and every parameter with type, default, range."""
    lines = [f"usage: {prog} [--ros-args -p NAME:=VALUE ...]", "", doc.strip().split("\n\n")[0],
             "", "parameters:"]
    for param in table:
        allowed = param.allowed()
        lines.append(f"  {param.name} ({_TYPE_NAMES[param.type]}, default "
                     f"{param.default!r}{', ' + allowed if allowed else ''})")
        lines.append(f"      {param.help}")
    return "\n".join(lines)


def make_executor(kind: str | None = None):
    """EventsExecutor (about 0.4 ms per cross-process round trip here, against 0.65 ms for the
    SingleThreadedExecutor); always spun with a finite timeout (see spin). ECONET_EXECUTOR=single
    chooses the other."""
    kind = kind or os.environ.get("ECONET_EXECUTOR", "events")
    if kind == "events":
        from rclpy.experimental import EventsExecutor
        return EventsExecutor()
    if kind == "single":
        return rclpy.executors.SingleThreadedExecutor()
    raise ConfigError(f"unknown executor '{kind}' (choose events or single)")


_STOP = threading.Event()


class Stopped(Exception):
    """SIGINT or SIGTERM asked the node to stop (raised between callbacks, by check_stop)."""


def stop_requested() -> bool:
    return _STOP.is_set()


def check_stop() -> None:
    """Raise Stopped if a signal asked the node to stop; loops that spin call this."""
    if _STOP.is_set():
        raise Stopped


def spin(node: Node, executor) -> None:
    """Serve the node's callbacks until a signal or shutdown (see serve)."""
    executor.add_node(node)
    serve(executor)


def serve(executor, timeout_sec: float = 0.5) -> None:
    """Serve the executor's nodes until a signal or shutdown. A finite timeout: the
    EventsExecutor spun without one busy-loops, and the stop flag is looked at between spins."""
    while rclpy.ok() and not stop_requested():
        executor.spin_once(timeout_sec=timeout_sec)


def _catch_signals() -> None:
    """SIGINT and SIGTERM set the stop flag instead of raising KeyboardInterrupt anywhere (e.g.
    halfway through closing a bag) or killing the process."""
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, lambda *_: _STOP.set())


def wants_help(args: list[str]) -> bool:
    """Whether the command line, before any --ros-args, asks for --help (or -h)."""
    ours = args[:args.index("--ros-args")] if "--ros-args" in args else args
    return "--help" in ours or "-h" in ours


def print_help(text: str) -> int:
    try:
        print(text, flush=True)
    except BrokenPipeError:                 # `--help | head`: the reader had enough
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    return 0


def run_node(prog: str, make: Callable[[], Node], args: list[str] | None = None,
             body: Callable[[Node, object], int | None] | None = None,
             parameters: tuple[Param, ...] = (), doc: str = "") -> int:
    """Start rclpy, build the node, serve it (or run body(node, executor)). --help prints the
    parameters and starts nothing; bad input ends in one line on stderr and exit status 2;
    SIGINT and SIGTERM end quietly with status 0, whatever was running then."""
    args = sys.argv if args is None else args
    if wants_help(args):
        return print_help(usage(prog, doc, parameters))

    def run(nodes: list[Node], executor) -> int | None:
        return serve(executor) if body is None else body(nodes[0], executor)
    return run_nodes(prog, args, [make], run)


def run_nodes(prog: str, args: list[str], makers: list[Callable[[], Node]],
              run: Callable[[list[Node], object], int | None]) -> int:
    """rclpy started with ``args`` (its global arguments), the nodes built in order and added
    to one executor, then run(nodes, executor); every node is destroyed at the end. An
    EconetError is one line on stderr (exit 2), naming options as node parameters
    (overwrite:=true), a signal a quiet end (exit 0)."""
    with options_as_parameters():
        return _run_nodes(prog, args, makers, run)


def _run_nodes(prog: str, args: list[str], makers: list[Callable[[], Node]],
               run: Callable[[list[Node], object], int | None]) -> int:
    _catch_signals()
    try:
        rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    except Exception as error:  # noqa: BLE001 - rclpy's argument parser: one line
        print(f"{prog}: error: {str(error).strip().splitlines()[0]}", file=sys.stderr)
        return 2
    nodes: list[Node] = []
    status = 0
    try:
        executor = make_executor()
        for make in makers:
            nodes.append(make())
            executor.add_node(nodes[-1])
        status = run(nodes, executor) or 0
    except EconetError as error:
        print(f"{prog}: error: {error}", file=sys.stderr)
        status = 2
    except Stopped:
        status = 0
    finally:
        for node in reversed(nodes):
            try:
                node.destroy_node()
            except Exception:  # noqa: BLE001 - shutting down anyway
                pass
        if rclpy.ok():
            rclpy.try_shutdown()
    return status

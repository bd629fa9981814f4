"""Every documented way to start a graph, run at small sizes: the launch file (its description
built with stand-ins for the launch package, which is not installable here, then what it would
start run as processes), scripts/graph-demo, graph_node's docstring example and the commands of
docs/ros-graph.md. Each writes what `econet evolve` writes for the same controller, its
controller record (run-NN/controller.json) included."""
import importlib.util
import os
import re
import shlex
import subprocess
import sys
import types

import pytest

from graph_helpers import REPO

SMALL = {"population": 6, "parents": 2, "trials": 2, "cycles": 20, "generations": 2, "seed": 3}
FILES = ("run.json", "metrics.csv", "genomes.npy", "fitness.npy", "best_genomes.npy",
         "controller.json")
DOMAIN = 1 + 7 * (os.getpid() % 4)      # 1-28, free of the other modules'; +0..6 per test


def small(**more) -> list[str]:
    return [f"{k}:={v}" for k, v in {**SMALL, "linger_sec": 0.0, **more}.items()]


def cli_run(out, controller=None, condition=None):
    """What `econet evolve --runs 1` writes with the SMALL settings (run-01)."""
    from econet_ros.cli.main import main

    given = {**SMALL, "controller": controller, "condition": condition}
    flags = [x for k, v in given.items() if v is not None for x in (f"--{k}", str(v))]
    assert main(["evolve", "--runs", "1", "--quiet", "--out", str(out), *flags]) == 0
    return out / "run-01"


def assert_same_run(got, want):
    for name in FILES:
        assert (got / name).exists() == (want / name).exists(), name
        if (want / name).exists():
            assert (got / name).read_bytes() == (want / name).read_bytes(), name


def run(command, domain, timeout=240):
    proc = subprocess.run([str(x) for x in command], cwd=REPO, capture_output=True, text=True,
                          timeout=timeout, env={**os.environ, "ROS_DOMAIN_ID": str(domain)})
    assert proc.returncode == 0, proc.stdout + proc.stderr
    return proc


def with_sections(command, **extra):
    """A graph_node command line with ``extra`` parameters (name:=value lists) appended to the
    named nodes' sections (a later -p wins)."""
    from econet_ros.nodes.graph_node import split_sections

    shared, sections = split_sections(command)
    for name, params in extra.items():
        sections[name] += [x for p in params for x in ("-p", p)]
    return [*shared, *[x for name, args in sections.items() for x in (name, *args)]]


# -- the launch file, with stand-ins for launch and launch_ros ------------------------------------
class Action:
    def __init__(self, *args, **kwargs):
        self.args, self.kwargs = args, kwargs


class If(Action):
    pass


class Unless(Action):
    pass


class LaunchConfiguration:
    def __init__(self, name):
        self.name = name


def load_launch_file(monkeypatch):
    stand_ins = {"launch": {"LaunchDescription": Action},
                 "launch.actions": {"DeclareLaunchArgument": Action},
                 "launch.conditions": {"IfCondition": If, "UnlessCondition": Unless},
                 "launch.substitutions": {"LaunchConfiguration": LaunchConfiguration},
                 "launch_ros": {}, "launch_ros.actions": {"Node": Action}}
    for name, attributes in stand_ins.items():
        monkeypatch.setitem(sys.modules, name, types.SimpleNamespace(**attributes))
    spec = importlib.util.spec_from_file_location(
        "econet_graph_launch", REPO / "launch" / "econet_graph.launch.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def launched(monkeypatch, **arguments) -> dict[str, dict]:
    """What `ros2 launch econet_ros econet_graph.launch.py name:=value ...` starts:
    {executable: {"parameters": {name: value}, "arguments": [...]}}, substitutions resolved."""
    actions = load_launch_file(monkeypatch).generate_launch_description().args[0]
    values = {a.args[0]: a.kwargs["default_value"] for a in actions if "default_value" in a.kwargs}
    values.update({k: str(v) for k, v in arguments.items()})

    def resolved(value):
        if isinstance(value, LaunchConfiguration):
            return values[value.name]
        return "".join(map(resolved, value)) if isinstance(value, list) else value

    started = {}
    for node in (a for a in actions if "executable" in a.kwargs):
        condition = node.kwargs["condition"]
        if (resolved(condition.args[0]) == "true") != isinstance(condition, If):
            continue
        started[node.kwargs["executable"]] = {
            "parameters": {k: resolved(v) for p in node.kwargs.get("parameters", [])
                           for k, v in p.items()},
            "arguments": [resolved(a) for a in node.kwargs.get("arguments", [])]}
    return started


def test_the_launch_file_gives_controller_to_the_controller_node(monkeypatch):
    from econet_ros.nodes.graph_node import split_sections

    apart = launched(monkeypatch, controller="random")
    assert set(apart) == {"world_node", "controller_node", "supervisor_node"}
    supervisor = apart["supervisor_node"]["parameters"]
    assert supervisor["controller"] == "random"
    assert apart["controller_node"]["parameters"] == {
        "controller": "random", "condition": supervisor["condition"],
        "config": supervisor["config"]}
    composed = launched(monkeypatch, controller="random", composed="true")
    _, sections = split_sections(composed["graph_node"]["arguments"])
    assert "controller:='random'" in sections["controller"]
    assert "controller:='random'" in sections["supervisor"]


@pytest.mark.ros
def test_what_the_launch_file_starts_evolves_the_named_controller(monkeypatch, tmp_path):
    want = cli_run(tmp_path / "cli", "random")
    sizes = {**SMALL, "linger_sec": 0.0}
    composed = launched(monkeypatch, composed="true", controller="random",
                        out=tmp_path / "composed", **sizes)
    run([sys.executable, "-m", "econet_ros.nodes.graph_node",
         *composed["graph_node"]["arguments"]], DOMAIN)
    assert_same_run(tmp_path / "composed" / "run-01", want)

    section = load_launch_file(monkeypatch).section     # name:=value as ROS arguments

    def ros_args(parameters):
        return ["".join(x) if isinstance(x, list) else x for x in section("", parameters)[1:]]
    apart = launched(monkeypatch, controller="random", out=tmp_path / "apart", **sizes)
    procs = [subprocess.Popen(
        [sys.executable, "-m", f"econet_ros.nodes.{name}",
         *ros_args(apart[name]["parameters"])], cwd=REPO,
        env={**os.environ, "ROS_DOMAIN_ID": str(DOMAIN + 1)}, stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT, text=True) for name in ("world_node", "controller_node")]
    try:
        run([sys.executable, "-m", "econet_ros.nodes.supervisor_node",
             *ros_args(apart["supervisor_node"]["parameters"])],
            DOMAIN + 1)
    finally:
        for proc in procs:
            proc.terminate()
            proc.wait(30)
    assert_same_run(tmp_path / "apart" / "run-01", want)


# -- scripts/graph-demo ---------------------------------------------------------------------------
@pytest.mark.ros
def test_graph_demo_records_the_controller_as_econet_evolve_does(tmp_path):
    want = cli_run(tmp_path / "cli", "three-layer")
    for offset, mode in ((2, ["--composed"]), (3, [])):
        out = tmp_path / (mode[0][2:] if mode else "apart")
        run([REPO / "scripts" / "graph-demo", *mode, out, "controller:=three-layer", *small()],
            DOMAIN + offset)
        assert_same_run(out / "run-01", want)
    # resumed by the other writer: the graph's folder is the CLI's, so evolve finds it done
    cli_run(tmp_path / "composed", "three-layer")
    assert_same_run(tmp_path / "composed" / "run-01", want)


# -- the commands in docstrings and docs -----------------------------------------------------------
def documented(text: str, start: str) -> list[str]:
    """The command that begins with ``start`` in ``text`` (continued over backslashed lines),
    as words."""
    found = re.search(re.escape(start) + r"(?:[^\n]*\\\n)*[^\n]*", text)
    assert found, f"no command {start!r} in the text"
    return shlex.split(found.group(0).replace("\\\n", " "))


@pytest.mark.ros
def test_the_example_of_graph_nodes_docstring_runs_as_written(tmp_path):
    from econet_ros.nodes import graph_node

    example = documented(graph_node.__doc__, "graph_node --ros-args")
    command = with_sections(example[1:], supervisor=small(out=tmp_path))
    run([REPO / "install" / "econet_ros" / "lib" / "econet_ros" / "graph_node", *command],
        DOMAIN + 4)
    controller = dict(p.split(":=") for p in example if ":=" in p)["controller"]
    assert_same_run(tmp_path / "run-01", cli_run(tmp_path / "cli", controller))


@pytest.mark.ros
def test_the_composed_graph_of_the_ros_graph_page_runs(tmp_path):
    page = (REPO / "docs" / "ros-graph.md").read_text()
    example = documented(page, "scripts/node graph --ros-args")
    command = with_sections(example[2:], supervisor=small(out=tmp_path / "graph"),
                            recorder=[f"out:={tmp_path / 'bag'}"])
    run([REPO / "scripts" / "node", "graph", *command], DOMAIN + 5)
    assert (tmp_path / "bag" / "metadata.yaml").exists()
    named = dict(p.split(":=") for p in example if ":=" in p)
    assert_same_run(tmp_path / "graph" / "run-01",
                    cli_run(tmp_path / "cli", named.get("controller"), named.get("condition")))


@pytest.mark.ros
def test_the_nodes_apart_of_the_ros_graph_page_evolve(tmp_path):
    page = (REPO / "docs" / "ros-graph.md").read_text()
    env = {**os.environ, "ROS_DOMAIN_ID": str(DOMAIN + 6)}
    procs = [subprocess.Popen([REPO / "scripts" / "node", name], cwd=REPO, env=env,
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
             for name in ("world", "controller")]
    try:
        supervisor = documented(page, "scripts/node supervisor --ros-args")
        run([REPO / supervisor[0], *supervisor[1:],
             *[x for p in small(out=tmp_path / "graph") for x in ("-p", p)]], DOMAIN + 6)
    finally:
        for proc in procs:
            proc.terminate()
            proc.wait(30)
    assert_same_run(tmp_path / "graph" / "run-01", cli_run(tmp_path / "cli"))


@pytest.mark.ros
def test_two_controllers_named_in_one_graph_are_a_one_line_error(tmp_path):
    proc = subprocess.run(
        [sys.executable, "-m", "econet_ros.nodes.graph_node", "controller", "--ros-args", "-p",
         "controller:=random", "supervisor", "--ros-args", "-p", "controller:=three-layer",
         "-p", f"out:={tmp_path}"], cwd=REPO, capture_output=True, text=True, timeout=120,
        env={**os.environ, "ROS_DOMAIN_ID": str(DOMAIN)})
    assert proc.returncode == 2
    assert proc.stderr.strip().splitlines()[-1] == (
        "graph_node: error: supervisor: controller:=three-layer, but the controller node's "
        "section says controller:=random; name it once")
    assert not list(tmp_path.glob("run-*"))

"""Finding plug-ins by name, so that other packages can plug their own in: controllers, the
decision rules a sweep names (science/sweeps/rules.py) and verbs of `econet sweep`
(cli/sweep.py), each kind in its entry-point group.

A plug-in name is one of
    * a name registered in the kind's entry-point group by any installed package (this
      distribution registers its own in setup.cfg, [options.entry_points]: the paper's
      ``normal``, ``three-layer`` and ``random`` controllers, the ``reacher``, and the rules and
      verbs of the studies wing), or
    * ``module:Class``, naming a class on the Python path directly.
Either way the class must subclass the kind's base class (a controller:
``econet_ros.controllers.Controller``, constructed as ``Class(n_envs, config)``). The command
line, the evolution, the controller node and the supervisor all resolve controller names here
(``make_controller``), and ``chosen_controller`` is the one rule for which controller a run
evolves.
"""
from __future__ import annotations

import configparser
import importlib
import inspect
from dataclasses import dataclass
from importlib.metadata import entry_points
from pathlib import Path

from .config import Config
from .controllers import Controller
from .errors import PluginError

EXTERNAL = "external"     # the supervisor's controller:=external: a node it does not know
# This distribution's registrations, read from the checkout when its metadata is not installed
# (running straight from a source tree) or is older than the checkout.
SETUP_CFG = Path(__file__).resolve().parent.parent / "setup.cfg"


@dataclass(frozen=True)
class Kind:
    """A kind of plug-in: what it is called in errors, its entry-point group, its base class."""

    what: str
    group: str
    base: type


CONTROLLERS = Kind("controller", "econet_ros.controllers", Controller)
GROUP = CONTROLLERS.group


def declared(group: str, path: Path = SETUP_CFG) -> dict[str, str]:
    """The names a group's entry points declare in setup.cfg ({} without the file)."""
    parser = configparser.ConfigParser(interpolation=None)
    parser.read(path, encoding="utf-8")
    lines = parser.get("options.entry_points", group, fallback="").splitlines()
    pairs = (line.split("=", 1) for line in lines if "=" in line)
    return {name.strip(): target.strip() for name, target in pairs}


def registered_in(kind: Kind) -> dict[str, str]:
    """Every registered name of a kind and the ``module:Class`` it stands for."""
    names = declared(kind.group)
    names.update({ep.name: ep.value for ep in entry_points(group=kind.group)})
    return names


def find(kind: Kind, name: str) -> type:
    """The class a name of the kind stands for (PluginError, one line, if there is none)."""
    names = registered_in(kind)
    target = names.get(name, name)
    module_name, sep, attribute = target.partition(":")
    if not sep or not module_name or not attribute:
        raise PluginError(f"unknown {kind.what} '{name}': not a registered name "
                          f"({', '.join(sorted(names))}) and not module:Class")
    try:
        module = importlib.import_module(module_name)
    except ImportError as error:
        raise PluginError(f"{kind.what} '{name}': cannot import module '{module_name}' "
                          f"({error})") from None
    cls = getattr(module, attribute, None)
    if cls is None:
        raise PluginError(f"{kind.what} '{name}': module '{module_name}' has no "
                          f"'{attribute}'")
    if not (inspect.isclass(cls) and issubclass(cls, kind.base)):
        raise PluginError(f"{kind.what} '{name}': {target} is not a subclass of "
                          f"{kind.base.__module__}.{kind.base.__qualname__}")
    if inspect.isabstract(cls):
        missing = ", ".join(sorted(cls.__abstractmethods__))
        raise PluginError(f"{kind.what} '{name}': {target} does not implement {missing}")
    return cls


def registered() -> dict[str, str]:
    """Every registered controller name and the ``module:Class`` it stands for."""
    return registered_in(CONTROLLERS)


def resolve(name: str) -> type:
    """The Controller class a name stands for (PluginError if there is none)."""
    return find(CONTROLLERS, name)


def make_controller(name: str, n_envs: int, config: Config) -> Controller:
    """A controller by name: a paper condition ('normal', 'three-layer', 'random'), any other
    registered plug-in (e.g. 'reacher'), or 'module:Class'."""
    return resolve(name)(n_envs, config)


def chosen_controller(condition: str, controller: str = "") -> str:
    """The controller a run evolves, and a graph's controller node runs: the one named, else
    the condition's own network. The supervisor and the controller node decide with it from
    the same two parameters, whoever starts them (graph_node, scripts/graph-demo, the launch
    file), so the two cannot disagree."""
    return controller or condition

"""Finding controllers by name, so that other packages can plug their own in.

A controller name is one of
    * a name registered in the entry-point group ``econet_ros.controllers`` by any installed
      package (this package registers the paper's ``normal``, ``three-layer`` and ``random``
      controllers and the ``reacher`` there too), or
    * ``module:Class``, naming a class on the Python path directly.
Either way the class must subclass ``econet_ros.controllers.Controller`` and is constructed as
``Class(n_envs, config)``. The command line, the evolution, the controller node and the
supervisor all resolve names here (``make_controller``), and ``chosen_controller`` is the one
rule for which controller a run evolves.
"""
from __future__ import annotations

import importlib
import inspect
from importlib.metadata import entry_points

from .config import Config
from .controllers import Controller
from .errors import PluginError

GROUP = "econet_ros.controllers"
EXTERNAL = "external"     # the supervisor's controller:=external: a node it does not know

# Our own registrations, also listed in setup.py; used when the package's metadata is not
# installed (running straight from a source tree).
BUILTIN = {
    "normal": "econet_ros.controllers:FourLayerNetwork",
    "three-layer": "econet_ros.controllers:ThreeLayerNetwork",
    "random": "econet_ros.controllers:RandomMovement",
    "reacher": "econet_ros.reacher:HandWrittenReacher",
}


def registered() -> dict[str, str]:
    """Every registered controller name and the ``module:Class`` it stands for."""
    names = dict(BUILTIN)
    names.update({ep.name: ep.value for ep in entry_points(group=GROUP)})
    return names


def resolve(name: str) -> type:
    """The Controller class a name stands for (PluginError if there is none)."""
    target = registered().get(name, name)
    module_name, sep, attribute = target.partition(":")
    if not sep or not module_name or not attribute:
        raise PluginError(f"unknown controller '{name}': not a registered name "
                          f"({', '.join(sorted(registered()))}) and not module:Class")
    try:
        module = importlib.import_module(module_name)
    except ImportError as error:
        raise PluginError(f"controller '{name}': cannot import module '{module_name}' "
                          f"({error})") from None
    cls = getattr(module, attribute, None)
    if cls is None:
        raise PluginError(f"controller '{name}': module '{module_name}' has no "
                          f"'{attribute}'")
    if not (inspect.isclass(cls) and issubclass(cls, Controller)):
        raise PluginError(f"controller '{name}': {target} is not a subclass of "
                          "econet_ros.controllers.Controller")
    if inspect.isabstract(cls):
        missing = ", ".join(sorted(cls.__abstractmethods__))
        raise PluginError(f"controller '{name}': {target} does not implement {missing}")
    return cls


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

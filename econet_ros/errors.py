"""The project's errors: one base, EconetError, whose message is one line meant for the user.

The command line (econet_ros.cli.main) and the node runner (econet_ros.nodes.runner) each catch
EconetError once and print it as ``<program>: error: <message>`` with exit status 2; nothing
else turns errors into text. The kinds say which contract was broken, so callers that can do
something about one kind (a retry, a refusal reply) catch just that kind. A message that tells
the user what to pass names it as that user gives it (``option``): ``--overwrite`` on the
command line, ``overwrite:=true`` for a node (the node runner says so with
``options_as_parameters``).
"""
from __future__ import annotations

from contextlib import contextmanager
from contextvars import ContextVar
from typing import Iterator

_AS_PARAMETERS = ContextVar("options are node parameters", default=False)


@contextmanager
def options_as_parameters() -> Iterator[None]:
    """Within this block messages name options as node parameters (name:=value)."""
    token = _AS_PARAMETERS.set(True)
    try:
        yield
    finally:
        _AS_PARAMETERS.reset(token)


def option(name: str, value: str | bool = True) -> str:
    """An option as the user gives it here: --name VALUE, or name:=VALUE to a node; True is a
    switch turned on (--overwrite, overwrite:=true), "" the option left empty or out."""
    if _AS_PARAMETERS.get():
        return f"{name}:={'true' if value is True else value or repr('')}"
    flag = f"--{name.replace('_', '-')}"
    return flag if value is True else (f"{flag} {value}" if value else f"no {flag}")


class EconetError(Exception):
    """Bad input or a state that cannot work; str(error) is one line for the user."""


class ConfigError(EconetError, ValueError):
    """A setting (config file, --set, a ROS parameter, a sweep spec) that cannot work."""


class SetupError(EconetError, ValueError):
    """Trial starts the world cannot take (object out of reach, joint outside its range...)."""


class ActionError(EconetError, ValueError):
    """A motor command the world cannot apply (wrong shape, NaN or infinite values)."""


class PluginError(EconetError, ValueError):
    """A controller name that cannot be used."""


class UsageError(EconetError):
    """Bad command-line input or an output path that cannot be written."""


class ResultsError(EconetError):
    """A run or study folder that cannot be read, resumed or analysed."""


class BagError(EconetError):
    """A bag that cannot be written or read."""


class WireError(EconetError, ValueError):
    """Bytes that are not a message of the expected type."""


class GraphError(EconetError):
    """The node graph cannot do what was asked (a node refused a request, or vanished)."""


class DeviceError(EconetError):
    """A device (--device cuda) that cannot be used here: no numba-cuda, no GPU, or a
    controller that cannot run on it."""

"""What every ``econet`` command shares: the parser that fails in one line, and options generated
from the config's own field declarations (econet_ros.config.SETTINGS), so each setting's name,
help text and allowed values are declared once, in config.py."""
from __future__ import annotations

import argparse
import json

from ..config import SETTINGS, Config, Setting, load_config
from ..devices import DEVICES
from ..errors import UsageError


class Parser(argparse.ArgumentParser):
    """An ArgumentParser whose errors are a UsageError (one line, exit 2) instead of usage text."""

    def error(self, message: str) -> None:
        raise UsageError(message)


def whole_number(low: int):
    """An argparse type: a whole number of at least ``low``, or a one-line error."""
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            value = low - 1
        if value < low:
            raise argparse.ArgumentTypeError(f"must be a whole number of at least {low}, "
                                             f"got {text}")
        return value
    return parse


positive = whole_number(1)
seed = whole_number(0)        # numpy's generators take whole numbers from 0 up


def key_value(text: str) -> tuple[str, object]:
    """KEY=VALUE, the value read as JSON when it is JSON (numbers, true/false) else as text."""
    key, sep, value = text.partition("=")
    if not sep:
        raise argparse.ArgumentTypeError(f"expected KEY=VALUE, got '{text}'")
    try:
        return key, json.loads(value)
    except json.JSONDecodeError:
        return key, value


def _truth(text: str) -> bool:
    if text.lower() in ("true", "1", "yes"):
        return True
    if text.lower() in ("false", "0", "no"):
        return False
    raise argparse.ArgumentTypeError(f"expected true or false, got '{text}'")


def option_name(item: Setting) -> str:
    return "--" + item.name.replace("_", "-")


def add_config_options(parser: argparse.ArgumentParser, sections: tuple[str, ...],
                       skip: tuple[str, ...] = ()) -> None:
    """--config, --set, and one option per setting of the given sections (except ``skip``,
    dotted keys), each documented by its config field."""
    parser.add_argument("--config", metavar="FILE",
                        help="JSON file of settings (see docs/assumptions.md); the options "
                             "below override it")
    parser.add_argument("--set", metavar="KEY=VALUE", type=key_value, action="append",
                        default=[], help="change any setting by its dotted name, e.g. --set "
                                         "model.object_radius=3")
    for section in sections:
        group = parser.add_argument_group(f"{section} settings")
        for item in (s for s in SETTINGS if s.section == section and s.key not in skip):
            kind = _truth if item.type is bool else item.type
            group.add_argument(option_name(item), dest=f"setting:{item.key}", type=kind,
                               default=None, choices=item.choices,
                               metavar=None if item.choices else item.type.__name__.upper(),
                               help=f"{item.describe()} (default: {item.default})")


def config_from(args: argparse.Namespace, **fixed: object) -> Config:
    """The Config the options describe: the --config file (or the defaults), then the options
    given, then --set, then ``fixed`` (dotted keys); validated (ConfigError on a bad value)."""
    base = load_config(args.config) if args.config else Config()
    changes = {key.partition(":")[2]: value for key, value in vars(args).items()
               if key.startswith("setting:") and value is not None}
    changes.update(dict(args.set))
    changes.update(fixed)
    return base.replace(**changes)


def add_run_options(parser: argparse.ArgumentParser, out: str) -> None:
    """Options of every command that evolves runs into an output folder."""
    parser.add_argument("--out", default=out, help="output folder (default: %(default)s)")
    parser.add_argument("--runs", type=positive, default=10,
                        help="independent runs (default: %(default)s, as in the paper)")
    parser.add_argument("--seed", type=seed, default=1,
                        help="base random seed; a run is a pure function of it (default: 1)")
    parser.add_argument("--overwrite", action="store_true",
                        help="replace results made with other settings instead of refusing")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")


def add_device_option(parser: argparse.ArgumentParser) -> None:
    """--device: where the trials run; the results are the same files either way."""
    parser.add_argument("--device", choices=tuple(DEVICES), default="cpu",
                        help="where the trials run: cpu (default), or cuda, an NVIDIA GPU "
                             "through numba-cuda (pip install \".[cuda]\"); the result files "
                             "are the same either way (docs/speed.md)")

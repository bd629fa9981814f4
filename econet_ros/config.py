"""Every parameter of the model and the experiment, each declared once, with the paper's value
or our documented assumption as its default (docs/assumptions.md explains each choice).

A field carries its help text, whether the paper fixes it, and its allowed values; the command
line's options, the supervisor node's ROS parameters and the launch file's arguments are all
generated from these declarations (``SETTINGS``), so they cannot drift apart.

A Config is immutable and JSON-serialisable; result folders store it so that any later analysis
or resume runs against exactly the model that produced the data.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field, fields
from typing import Any, NamedTuple

from .errors import ConfigError

CONDITIONS = ("normal", "three-layer", "random")
MUTATIONS = ("per-bit", "exact", "weights")         # genome.mutate's modes
CODES = ("binary", "gray", "sign-magnitude")        # genome.decode's codes
BODY_AXES = ("unbounded", "within-360")
SHOULDER_CONVENTIONS = ("centred", "forward")
ANGLE_STEPS = ("continuous", "round", "truncate")   # world.move's moves per cycle
JOINT_LIMITS = ("clip", "cancel")
OPTIMIZERS = ("ga", "cmaes", "es")                  # optimizers.py
WIRINGS = ("modular", "scrambled")                  # controllers.FourLayerNetwork


def setting(default: Any, help: str, *, paper: bool = False, choices: tuple | None = None,
            low: float | None = None, high: float | None = None, added: bool = False):
    """A config field: default, help text, whether the paper states it (else it is our
    assumption), and the values it may take (choices, or the closed range low..high).

    added: the setting came after result format 1; it is stored (run.json, bags) only when it
    differs from its default, so older folders, which lack it, read as the default and results
    of the default model stay byte-identical."""
    return field(default=default, metadata={"help": help, "paper": paper, "choices": choices,
                                            "low": low, "high": high, "added": added})


@dataclass(frozen=True)
class ModelConfig:
    """The body, the senses and the environment (paper: The environment, The econet, Appendix)."""

    workspace_size: float = setting(100.0, "workspace width; the agent sits at its centre",
                                    paper=True, low=1.0)
    segment_length: float = setting(25.0, "length of each arm segment", paper=True, low=1e-3)
    hand_length: float = setting(5.0, "the hand: the last units of the forearm", paper=True,
                                 low=1e-3)
    field_of_view_deg: float = setting(64.0, "visual field in degrees", paper=True, low=1.0,
                                       high=359.0)
    windows_per_unit: int = setting(8, "one-degree windows per visual unit", paper=True, low=1)
    visual_units: int = setting(8, "visual input units", paper=True, low=1)
    visual_range: float = setting(50.0, "distance that normalises vision (the arm's length)",
                                  paper=True, low=1e-3)
    max_rotation_deg: float = setting(15.0, "most degrees per cycle for eye and joints",
                                      paper=True, low=0.0, high=180.0)
    joint_max_deg: float = setting(180.0, "shoulder and elbow range 0..this (degrees)",
                                   paper=True, low=1.0, high=360.0)
    object_radius: float = setting(2.0, "radius of the disk-shaped object ('a small object')",
                                   low=1e-3, high=50.0)
    reach_min: float = setting(10.0, "nearest object centre from the agent", low=0.0)
    reach_max: float = setting(45.0, "farthest object centre from the agent", low=0.0)
    start_posture: str = setting("random", "trial start: random body axis and joints, or "
                                 "'extended' (gaze +x, arm straight out)",
                                 choices=("random", "extended"))
    body_axis: str = setting("unbounded", "body/eye axis: 'unbounded' (turns any number of "
                             "circles) or 'within-360' (stops 360 degrees either side of its "
                             "trial start: 'a full 360 degrees in either direction')",
                             choices=BODY_AXES, added=True)
    shoulder_convention: str = setting("centred", "shoulder range: 'centred' (0-180 spans 90 "
                                       "degrees either side of the gaze; extended = 90 right) or "
                                       "'forward' (extended = along the gaze, flexing sweeps "
                                       "left to straight back); docs/assumptions.md",
                                       choices=SHOULDER_CONVENTIONS, added=True)
    angle_steps: str = setting("continuous", "each cycle's eye and joint moves: 'continuous', "
                               "or whole degrees, 'round'ed (half away from zero) or "
                               "'truncate'd (toward zero); trial starts are then whole degrees "
                               "too", choices=ANGLE_STEPS, added=True)
    joint_limit: str = setting("clip", "a joint move past 0 or joint_max_deg: 'clip' (stop at "
                               "the limit) or 'cancel' (that joint does not move that cycle)",
                               choices=JOINT_LIMITS, added=True)


@dataclass(frozen=True)
class NetworkConfig:
    """Network sizes (paper, Appendix). The paper does not give the four-layer net's hidden
    sizes: 2/2/4 (64 weights) is the setting the pre-registered confirmatory study chose (H1,
    docs/preregistrations.md); the a-priori 4/4/8 (160) is the study's variant hidden-4-4-8."""

    visual_hidden: int = setting(2, "four-layer net: visual hidden units (2: chosen by the "
                                 "confirmatory study; the a-priori reading was 4)", low=1,
                                 high=256)
    proprio_hidden: int = setting(2, "four-layer net: proprioceptive hidden units (2; a "
                                  "priori 4)", low=1, high=256)
    intermodal_hidden: int = setting(4, "four-layer net: intermodal hidden units (4; a priori "
                                     "8)", low=1, high=256)
    three_layer_hidden: int = setting(8, "three-layer net: hidden units ('eight units')",
                                      paper=True, low=1, high=256)
    first_layer_wiring: str = setting("modular", "four-layer net: 'modular' (the paper: visual "
                                      "hidden units read vision, proprioceptive ones "
                                      "proprioception) or 'scrambled' (the same units and "
                                      "weights, each unit reading a random subset of the same "
                                      "size of all vision and proprioception inputs, drawn from "
                                      "wiring_seed)", choices=WIRINGS, added=True)
    wiring_seed: int = setting(0, "four-layer net: the seed a scrambled wiring is drawn from",
                               low=0, added=True)


@dataclass(frozen=True)
class EvolutionConfig:
    """The variation-and-selection algorithm (paper: The learning algorithm, Appendix)."""

    condition: str = setting("normal", "network: normal (four-layer), three-layer, or random "
                             "movement", paper=True, choices=CONDITIONS)
    population: int = setting(100, "econets per generation", paper=True, low=1)
    parents: int = setting(20, "econets selected to reproduce", paper=True, low=1)
    trials: int = setting(20, "trials per econet per generation", paper=True, low=1)
    cycles: int = setting(100, "movement cycles per trial", paper=True, low=1)
    generations: int = setting(200, "generations per run", paper=True, low=1)
    weight_range: float = setting(10.0, "weights lie in [-this, this]", paper=True, low=1e-9)
    bits_per_weight: int = setting(8, "bits per weight in the genome", paper=True, low=1,
                                   high=16)
    mutation_rate: float = setting(0.02, "share of bits flipped when copying", paper=True,
                                   low=0.0, high=1.0)
    mutation_mode: str = setting("per-bit", "per-bit: each bit flips with mutation_rate "
                                 "(Appendix); exact: exactly that share of each genome's bits; "
                                 "weights: that share of weights each moves 1..mutation_step "
                                 "grid points up or down (body text)", choices=MUTATIONS)
    mutation_step: int = setting(4, "weights mutation: largest move, in grid points of "
                                 "2 x weight_range / (2^bits - 1) (0.078 in the paper's grid)",
                                 low=1, high=255, added=True)
    genome_code: str = setting("binary", "how a weight's grid point is coded in its bits: "
                               "binary, gray (neighbouring points differ in one bit), or "
                               "sign-magnitude (a sign bit and bits - 1 of magnitude: zero is a "
                               "code)", choices=CODES, added=True)
    shared_trials: bool = setting(True, "all econets of a generation face the same trials")
    optimizer: str = setting("ga", "what breeds each generation from the last one's fitness: "
                             "ga (the paper's selection and bit-flip mutation), cmaes (CMA-ES), "
                             "es (an OpenAI-style evolution strategy); docs/optimizers.md",
                             choices=OPTIMIZERS, added=True)
    cmaes_sigma: float = setting(3.0, "cmaes: initial step size, in weight units (chosen "
                                 "by a pilot; docs/optimizers.md)", low=1e-6, added=True)
    es_sigma: float = setting(1.0, "es: standard deviation of the perturbations, in weight "
                              "units (chosen by a pilot; docs/optimizers.md)", low=1e-6, added=True)
    es_learning_rate: float = setting(0.3, "es: Adam's step size, in weight units (chosen by "
                                      "a pilot; docs/optimizers.md)", low=1e-9, added=True)


SECTIONS = {"model": ModelConfig, "network": NetworkConfig, "evolution": EvolutionConfig}


class Setting(NamedTuple):
    """One config field as the generated interfaces see it."""

    section: str
    name: str
    default: Any
    type: type
    help: str
    paper: bool
    choices: tuple | None
    low: float | None
    high: float | None

    @property
    def key(self) -> str:
        return f"{self.section}.{self.name}"

    def describe(self) -> str:
        """The help text with where it comes from and what it allows, for --help and ROS."""
        allowed = ""
        if self.choices:
            allowed = f"; one of {', '.join(map(str, self.choices))}"
        elif self.low is not None or self.high is not None:
            allowed = f"; {_range_words(self)}"
        return f"{self.help} ({'paper' if self.paper else 'assumption'}{allowed})"


SETTINGS: tuple[Setting, ...] = tuple(
    Setting(section, f.name, f.default, type(f.default), f.metadata["help"],
            f.metadata["paper"], f.metadata["choices"], f.metadata["low"], f.metadata["high"])
    for section, cls in SECTIONS.items() for f in fields(cls))


def checked_value(item: Setting, value: Any) -> Any:
    """value as the setting's type (ints are accepted where floats are meant), or ConfigError
    naming the setting and what it allows."""
    kind = item.type
    if kind is bool:
        ok = isinstance(value, bool)
    elif kind is int:
        ok = isinstance(value, int) and not isinstance(value, bool)
    elif kind is float:
        ok = isinstance(value, (int, float)) and not isinstance(value, bool) \
            and math.isfinite(value)
        value = float(value) if ok else value
    else:
        ok = isinstance(value, kind)
    if not ok:
        raise ConfigError(f"{item.key} must be {_KIND_NAMES[kind]}, got {value!r}")
    if item.choices and value not in item.choices:
        raise ConfigError(f"{item.key} must be one of {', '.join(map(str, item.choices))}, "
                          f"got {value!r}")
    below = item.low is not None and value < item.low
    if below or (item.high is not None and value > item.high):
        raise ConfigError(f"{item.key} must be {_range_words(item)}, got {value!r}")
    return value


def _range_words(item: Setting) -> str:
    if item.low is None:
        return f"at most {item.high:g}"
    if item.high is None:
        return f"at least {item.low:g}"
    return f"between {item.low:g} and {item.high:g}"


_KIND_NAMES = {bool: "true or false", int: "a whole number", float: "a finite number",
               str: "a string"}


@dataclass(frozen=True)
class Config:
    model: ModelConfig = field(default_factory=ModelConfig)
    network: NetworkConfig = field(default_factory=NetworkConfig)
    evolution: EvolutionConfig = field(default_factory=EvolutionConfig)

    @property
    def offspring_per_parent(self) -> int:
        return self.evolution.population // self.evolution.parents

    def to_dict(self) -> dict:
        """Nested sections as stored in run.json (added settings only when not default)."""
        return {name: section_dict(getattr(self, name)) for name in SECTIONS}

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), indent=2, sort_keys=True)

    @classmethod
    def from_dict(cls, data: Any) -> "Config":
        """A validated Config from nested sections; missing settings take their defaults."""
        if not isinstance(data, dict):
            raise ConfigError(f"a config must be a JSON object of sections "
                              f"({', '.join(SECTIONS)}), got {type(data).__name__}")
        unknown = set(data) - set(SECTIONS)
        if unknown:
            raise ConfigError(f"unknown config section(s): {', '.join(sorted(unknown))}")
        parts = {name: section_from_dict(name, data.get(name, {})) for name in SECTIONS}
        return cls(**parts).validated()

    def replace(self, **dotted: object) -> "Config":
        """Copy with settings changed by dotted name, e.g. replace(**{"evolution.trials": 5})."""
        data = self.to_dict()
        known = {item.key for item in SETTINGS}
        for key, value in dotted.items():
            if key not in known:
                raise ConfigError(f"unknown setting '{key}'")
            section, _, name = key.partition(".")
            data[section][name] = value
        return Config.from_dict(data)

    def validated(self) -> "Config":
        """Return self, or raise ConfigError naming the first value that cannot work together
        with the others (each value's own type and range are checked on reading)."""
        m, e = self.model, self.evolution
        checks = [
            (e.parents <= e.population,
             f"parents must be between 1 and the population ({e.population}), got {e.parents}"),
            (e.population % e.parents == 0,
             f"population ({e.population}) must be a multiple of parents ({e.parents})"),
            (m.reach_min <= m.reach_max <= 2 * m.segment_length + m.object_radius,
             "reach_min/reach_max must satisfy 0 <= reach_min <= reach_max <= arm length + radius"),
            (m.visual_units * m.windows_per_unit == round(m.field_of_view_deg),
             "visual_units x windows_per_unit must equal the field of view in degrees"),
            (m.angle_steps == "continuous" or float(m.joint_max_deg).is_integer(),
             f"whole-degree angles (angle_steps={m.angle_steps}) need a whole joint_max_deg, got "
             f"{m.joint_max_deg:g}"),
            (e.genome_code != "sign-magnitude" or e.bits_per_weight >= 2,
             "the sign-magnitude genome code needs at least 2 bits_per_weight (a sign and a "
             "magnitude)"),
            (e.optimizer != "es" or e.population % 2 == 0,
             f"the es optimizer tests antithetic pairs: population must be even, got "
             f"{e.population}"),
        ]
        for ok, message in checks:
            if not ok:
                raise ConfigError(message)
        return self


def section_dict(section) -> dict:
    """One section's settings as stored: every field, except added ones at their default."""
    return {f.name: getattr(section, f.name) for f in fields(section)
            if not (f.metadata["added"] and getattr(section, f.name) == f.default)}


def section_from_dict(name: str, values: Any):
    """One section's dataclass from a dict of its settings, each checked on its own."""
    if not isinstance(values, dict):
        raise ConfigError(f"config section '{name}' must be a JSON object, got "
                          f"{type(values).__name__}")
    known = {s.name: s for s in SETTINGS if s.section == name}
    bad = set(values) - set(known)
    if bad:
        raise ConfigError(f"unknown {name} setting(s): {', '.join(sorted(bad))}")
    return SECTIONS[name](**{k: checked_value(known[k], v) for k, v in values.items()})


def load_config(path: str) -> Config:
    """Read a Config from a JSON file; missing settings take their defaults."""
    try:
        with open(path, encoding="utf-8") as handle:
            data = json.load(handle)
    except OSError as error:
        raise ConfigError(f"cannot read config {path}: {error.strerror}") from None
    except (json.JSONDecodeError, UnicodeDecodeError) as error:
        raise ConfigError(f"config {path} is not valid JSON: {error}") from None
    return Config.from_dict(data)


def model_json(model: ModelConfig) -> str:
    """The model section as the JSON a TrialStart message (and so every bag) carries."""
    return json.dumps(section_dict(model), sort_keys=True)


def model_from_json(text: str) -> ModelConfig:
    """The model a TrialStart's JSON describes (defaults when empty), validated."""
    if not text:
        return ModelConfig()
    try:
        values = json.loads(text)
    except json.JSONDecodeError as error:
        raise ConfigError(f"model settings are not valid JSON: {error}") from None
    return Config(model=section_from_dict("model", values)).validated().model

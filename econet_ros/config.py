"""Every parameter of the model and the experiment, with the paper's values or our documented
assumptions as defaults (see docs/assumptions.md, which explains each choice).

A Config is immutable and JSON-serialisable; result folders store it so that any later analysis
or resume runs against exactly the model that produced the data.
"""
from __future__ import annotations

import dataclasses
import json
from dataclasses import dataclass, field, fields

CONDITIONS = ("normal", "three-layer", "random")


class ConfigError(ValueError):
    """A configuration value that cannot work; the message is one line meant for the user."""


@dataclass(frozen=True)
class ModelConfig:
    """The body, the senses and the environment (paper: The environment, The econet, Appendix)."""

    workspace_size: float = 100.0        # paper: 100 x 100 units, agent at the centre
    segment_length: float = 25.0         # paper: each arm segment 25 units
    hand_length: float = 5.0             # paper: the hand is the last 5 units of the forearm
    field_of_view_deg: float = 64.0      # paper: 64 degree visual field
    windows_per_unit: int = 8            # paper: 64 one-degree windows, 8 per visual unit
    visual_units: int = 8                # paper: 8 visual input units
    visual_range: float = 50.0           # paper: distance normalised by 50 (the arm's length)
    max_rotation_deg: float = 15.0       # paper: at most 15 degrees per cycle for eye and joints
    joint_max_deg: float = 180.0         # paper: shoulder and elbow limited to 0-180 degrees
    object_radius: float = 2.0           # assumption: a disk of radius 2 ("a small object")
    reach_min: float = 10.0              # assumption: object centre 10-45 units from the agent
    reach_max: float = 45.0
    start_posture: str = "random"        # assumption: random body axis, shoulder and elbow each trial


@dataclass(frozen=True)
class NetworkConfig:
    """Network sizes (paper, Appendix; hidden sizes of the four-layer net are our assumption)."""

    visual_hidden: int = 4               # assumption
    proprio_hidden: int = 4              # assumption
    intermodal_hidden: int = 8           # assumption (the three-layer net's single layer has 8)
    three_layer_hidden: int = 8          # paper: "a single hidden layer with eight units"


@dataclass(frozen=True)
class EvolutionConfig:
    """The variation-and-selection algorithm (paper: The learning algorithm, Appendix)."""

    condition: str = "normal"
    population: int = 100                # paper
    parents: int = 20                    # paper: the 20 best are selected
    trials: int = 20                     # paper: 20 trials per econet
    cycles: int = 100                    # paper: 100 input-output cycles per trial
    generations: int = 200               # paper
    weight_range: float = 10.0           # paper: weights in [-10, 10]
    bits_per_weight: int = 8             # paper: 8 bits per weight
    mutation_rate: float = 0.02          # paper: 2% of bits flipped
    mutation_mode: str = "per-bit"       # assumption: each bit flips with p=2% ("exact": 2% of bits)
    shared_trials: bool = True           # assumption: all econets of a generation face the same 20 trials


@dataclass(frozen=True)
class Config:
    model: ModelConfig = field(default_factory=ModelConfig)
    network: NetworkConfig = field(default_factory=NetworkConfig)
    evolution: EvolutionConfig = field(default_factory=EvolutionConfig)

    @property
    def offspring_per_parent(self) -> int:
        return self.evolution.population // self.evolution.parents

    def to_dict(self) -> dict:
        return dataclasses.asdict(self)

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), indent=2, sort_keys=True)

    @classmethod
    def from_dict(cls, data: dict) -> "Config":
        sections = {"model": ModelConfig, "network": NetworkConfig, "evolution": EvolutionConfig}
        unknown = set(data) - set(sections)
        if unknown:
            raise ConfigError(f"unknown config section(s): {', '.join(sorted(unknown))}")
        parts = {}
        for name, section_cls in sections.items():
            values = data.get(name, {})
            known = {f.name for f in fields(section_cls)}
            bad = set(values) - known
            if bad:
                raise ConfigError(f"unknown {name} setting(s): {', '.join(sorted(bad))}")
            parts[name] = section_cls(**values)
        return cls(**parts).validated()

    def replace(self, **dotted: object) -> "Config":
        """Copy with settings changed by dotted name, e.g. replace(**{"evolution.trials": 5})."""
        data = self.to_dict()
        for key, value in dotted.items():
            section, _, name = key.partition(".")
            if section not in data or name not in data[section]:
                raise ConfigError(f"unknown setting '{key}'")
            data[section][name] = value
        return Config.from_dict(data)

    def validated(self) -> "Config":
        """Return self, or raise ConfigError naming the first value that cannot work."""
        m, n, e = self.model, self.network, self.evolution
        checks = [
            (e.condition in CONDITIONS,
             f"unknown condition '{e.condition}' (choose from {', '.join(CONDITIONS)})"),
            (e.population >= 1, f"population must be at least 1, got {e.population}"),
            (1 <= e.parents <= e.population,
             f"parents must be between 1 and the population ({e.population}), got {e.parents}"),
            (e.population % e.parents == 0,
             f"population ({e.population}) must be a multiple of parents ({e.parents})"),
            (e.trials >= 1, f"trials must be at least 1, got {e.trials}"),
            (e.cycles >= 1, f"cycles must be at least 1, got {e.cycles}"),
            (e.generations >= 1, f"generations must be at least 1, got {e.generations}"),
            (e.weight_range > 0, f"weight_range must be positive, got {e.weight_range}"),
            (1 <= e.bits_per_weight <= 16,
             f"bits_per_weight must be 1-16, got {e.bits_per_weight}"),
            (0.0 <= e.mutation_rate <= 1.0,
             f"mutation_rate must be in [0, 1], got {e.mutation_rate}"),
            (e.mutation_mode in ("per-bit", "exact"),
             f"mutation_mode must be 'per-bit' or 'exact', got '{e.mutation_mode}'"),
            (m.start_posture in ("random", "extended"),
             f"start_posture must be 'random' or 'extended', got '{m.start_posture}'"),
            (m.object_radius > 0, f"object_radius must be positive, got {m.object_radius}"),
            (0 <= m.reach_min <= m.reach_max <= 2 * m.segment_length + m.object_radius,
             "reach_min/reach_max must satisfy 0 <= reach_min <= reach_max <= arm length + radius"),
            (m.visual_units * m.windows_per_unit == round(m.field_of_view_deg),
             "visual_units x windows_per_unit must equal the field of view in degrees"),
            (min(n.visual_hidden, n.proprio_hidden, n.intermodal_hidden,
                 n.three_layer_hidden) >= 1, "hidden layer sizes must be at least 1"),
        ]
        for ok, message in checks:
            if not ok:
                raise ConfigError(message)
        return self


def load_config(path: str) -> Config:
    """Read a Config from a JSON file; missing settings take their defaults."""
    try:
        with open(path, encoding="utf-8") as handle:
            data = json.load(handle)
    except OSError as error:
        raise ConfigError(f"cannot read config {path}: {error.strerror}") from None
    except json.JSONDecodeError as error:
        raise ConfigError(f"config {path} is not valid JSON: {error}") from None
    return Config.from_dict(data)

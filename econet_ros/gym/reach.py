"""``econet_ros/Reach-v0``: one econet's reaching trial as a Gymnasium environment, over the
same World (econet_ros.world) as the evolution, the nodes and the benchmarks."""
from __future__ import annotations

from typing import Any

import gymnasium
import numpy as np
from gymnasium import spaces

from ..config import Config, ConfigError
from ..errors import ActionError, SetupError
from ..world import N_MOTOR, TrialSetup, World, n_inputs, sample_setups

# Reset options: each replaces the drawn value of that part of the trial start.
OPTIONS = ("object_xy", "body", "shoulder", "elbow")
ALL_OF_ONE = np.arange(1)      # the environments of a single environment's world


class ReachTask:
    """What the single and the vector environment share: a World of n environments, the spaces
    of one, and the rules that turn reset options into trial starts and actions into motor
    commands."""

    def __init__(self, n_envs: int, config: Config | None, cycles: int | None):
        self.config = config or Config()
        self.cycles = self.config.evolution.cycles if cycles is None else cycles
        if not isinstance(self.cycles, int) or self.cycles < 1:
            raise ConfigError(f"cycles (the trial length) must be a positive whole number, "
                              f"got {self.cycles!r}")
        model = self.config.model
        self.world = World(n_envs, model)
        self.observation_space = spaces.Box(0.0, 1.0, (n_inputs(model),),
                                            np.float64)
        self.action_space = spaces.Box(0.0, 1.0, (N_MOTOR,), np.float64)

    def setups(self, rng: np.random.Generator, envs: np.ndarray,
               options: dict | None) -> TrialSetup:
        """Trial starts for the environments ``envs``, drawn from rng as the evolution draws
        them, with any option's values in place of the drawn ones (one value for every
        environment, or one per environment of the world, of which envs' are taken). Whether
        they can be run is checked by World.reset/restart (SetupError)."""
        setup = sample_setups(rng, len(envs), self.config.model)
        options = dict(options or {})
        unknown = sorted(set(options) - set(OPTIONS))
        if unknown:
            raise SetupError(f"unknown reset option(s) {', '.join(unknown)}; the options are "
                             f"{', '.join(OPTIONS)}")
        n = self.world.n_envs
        for key, value in options.items():
            shape = (n, 2) if key == "object_xy" else (n,)
            try:
                values = np.broadcast_to(np.asarray(value, dtype=np.float64), shape)
            except (TypeError, ValueError):
                raise SetupError(f"reset option {key} must be numbers of shape {shape[1:]} or "
                                 f"{shape}, got {np.shape(value)}") from None
            setattr(setup, key, values[envs])
        return setup

    @staticmethod
    def motor(actions: Any, shape: tuple[int, ...]) -> np.ndarray:
        """The actions as a new float array of exactly ``shape`` (ActionError otherwise).
        Values outside [0, 1] are left to the world, which clips them; NaN or infinite values
        it refuses (ActionError)."""
        try:
            motor = np.array(actions, dtype=np.float64)
        except (TypeError, ValueError):
            raise ActionError(f"an action must be numbers of shape {shape}, got "
                              f"{type(actions).__name__}") from None
        if motor.shape != shape:
            raise ActionError(f"an action must have shape {shape}, got {motor.shape}")
        return motor


class ReachEnv(gymnasium.Env):
    """One econet's reaching trial (Schlesinger, Parisi & Langer, 2000), as in the evolution.

    ## Description
    A 2-D workspace with the agent at its centre: an eye/body axis that turns freely, a
    two-segment arm (shoulder and elbow, each 0-180 degrees) and a small disk-shaped object
    within reach. The agent sees with 8 visual units over a 64-degree field, feels its joint
    angles and touch, and drives five muscles. Geometry and conventions: econet_ros/world.py
    and docs/assumptions.md; the spaces follow the model's config (defaults below).

    ## Action Space
    ``Box(0, 1, (5,), float64)``: [eye, shoulder flexor, shoulder extensor, elbow flexor,
    elbow extensor]. The eye turns 30 * (eye - 0.5) degrees; each joint turns by
    -15 * (flexor - extensor) degrees and stops at its limits. Values outside [0, 1] are
    clipped to it by the world (Gymnasium's Box does not clip; the paper's logistic outputs
    never leave [0, 1]).

    ## Observation Space
    ``Box(0, 1, (13,), float64)``, the network's input layer: 0-7 vision (unit 0 at the right
    edge of the field; 1 - d/50 of the nearest visible hand or object point, averaged over the
    unit's eight one-degree windows), 8-11 proprioception (shoulder flexor q_s/180, extensor
    1 - q_s/180, then the same for the elbow), 12 touch (1 while the hand touches the object).

    ## Rewards
    1 for every step that ends with the hand touching the object, else 0: a trial's return is
    the paper's fitness of one trial.

    ## Starting State
    As in the evolution: the object uniformly over the reachable annulus (10-45 units from the
    agent, by area); body axis uniform in [0, 360), both joints uniform in [0, 180]
    (``model.start_posture = "extended"``: gaze along +x, arm straight out).

    ## Episode End
    Never terminated; truncated after ``cycles`` steps (the trial length, default 100).
    Stepping on after that, or before the first reset, raises ``gymnasium.error.ResetNeeded``.

    ## Arguments
    ``gymnasium.make("econet_ros/Reach-v0", config=None, cycles=None, render_mode=None)``:
    config, an ``econet_ros.config.Config`` (default: the paper's model); cycles, the trial
    length (default: ``config.evolution.cycles``); render_mode None or "rgb_array" (a 320 x 320
    RGB picture from econet_ros.recording.render).

    ## Reset options
    ``reset(seed=..., options={...})``: ``object_xy`` (x, y) of the object's centre,
    ``body``, ``shoulder``, ``elbow`` start angles in degrees; each replaces the drawn value,
    the rest are drawn as usual (the draws do not depend on the options, so a seed gives the
    same trial with or without them). ``reset(seed=s)`` draws the trial start exactly as
    ``world.sample_setups(numpy.random.default_rng(s), 1, model)``.

    ## Bad input
    One-line errors, all ``ValueError``s and ``econet_ros.errors.EconetError``s: an action of
    another shape, or with NaN or infinite values, raises ``ActionError`` (nothing moves); an
    unknown reset option, an object out of reach, a joint angle outside 0-180, a body angle
    outside -360-360 or a non-finite start raises ``SetupError``.

    ## Version History
    v0: the model of econet_ros 0.1.
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 10}

    def __init__(self, config: Config | None = None, cycles: int | None = None,
                 render_mode: str | None = None):
        if render_mode not in (None, *self.metadata["render_modes"]):
            raise ConfigError(f"render_mode must be None or 'rgb_array', got {render_mode!r}")
        self.task = ReachTask(1, config, cycles)
        self.observation_space = self.task.observation_space
        self.action_space = self.task.action_space
        self.render_mode = render_mode
        self.elapsed: int | None = None        # steps of the current trial; None before reset

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        obs = self.task.world.reset(self.task.setups(self.np_random, ALL_OF_ONE, options))
        self.elapsed = 0
        return self.task.world.senses[0], {"fixated": bool(obs.fixated[0])}

    def step(self, action):
        if self.elapsed is None or self.elapsed >= self.task.cycles:
            raise gymnasium.error.ResetNeeded("the trial has ended (or never started): call "
                                              "reset before step")
        obs = self.task.world.step(self.task.motor(action, (N_MOTOR,))[None])
        self.elapsed += 1
        return (self.task.world.senses[0], float(obs.touch[0]), False,
                self.elapsed >= self.task.cycles, {"fixated": bool(obs.fixated[0])})

    def render(self):
        """The current state as an RGB array (render_mode "rgb_array"), else None."""
        if self.render_mode != "rgb_array":
            return None
        from ..recording.render import TrialFrames, rgb_image   # matplotlib: only if asked

        world = self.task.world
        frames = TrialFrames(world.body, world.shoulder, world.elbow, world.senses[:, -1] > 0.5,
                             world.object_xy[0])
        return rgb_image(frames, world.model, 0, self.elapsed or 0)

"""The vector version of ``econet_ros/Reach-v0``: num_envs trials stepped by one call of the
batched World (one compiled, parallel kernel per step), with Gymnasium 1.x next-step
autoreset."""
from __future__ import annotations

import gymnasium
import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from ..config import Config, ConfigError
from ..errors import SetupError
from ..world import N_MOTOR
from .reach import ReachTask

# The command that leaves a state exactly as it is (the eye still, each muscle pair balanced):
# what an environment that restarts this step is given in place of its ignored action.
STILL = np.array([0.5, 0.0, 0.0, 0.0, 0.0])


class ReachVectorEnv(VectorEnv):
    """num_envs independent reaching trials in lockstep; each one is ``ReachEnv`` (same spaces,
    rewards, reset options, clipping and errors; options take one value for all environments
    or one per environment).

    Autoreset (``AutoresetMode.NEXT_STEP``, Gymnasium 1.x's default): every trial is truncated
    after ``cycles`` steps; on the following ``step`` that environment ignores its action and
    starts a new trial (drawn from the vector env's generator), returning the new trial's first
    observation with reward 0 and terminated = truncated = False. Trials started together stay
    in step, so with the default schedule all environments restart on the same step.

    Partial resets: ``reset(options={"reset_mask": mask})`` restarts the marked environments
    only (the others' trials go on), so trials can be staggered.

    ``info["fixated"]`` (with its mask ``info["_fixated"]``) says per environment whether the
    object is fixated, for analyses.
    """

    metadata = {"render_modes": [], "autoreset_mode": AutoresetMode.NEXT_STEP}

    def __init__(self, num_envs: int = 1, config: Config | None = None,
                 cycles: int | None = None, render_mode: str | None = None):
        if render_mode is not None:
            raise ConfigError("the vector environment does not render; make single "
                              "environments with render_mode='rgb_array' to watch trials")
        if not isinstance(num_envs, int) or num_envs < 1:
            raise ConfigError(f"num_envs must be a positive whole number, got {num_envs!r}")
        self.num_envs = num_envs
        self.task = ReachTask(num_envs, config, cycles)
        self.single_observation_space = self.task.observation_space
        self.single_action_space = self.task.action_space
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)
        self.render_mode = None
        self.elapsed = np.zeros(num_envs, dtype=np.int64)
        self.restarting = np.zeros(num_envs, dtype=bool)  # truncated last step: restart now
        self.started = False

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        """Start new trials in every environment, or with ``options["reset_mask"]`` (a bool
        array, one per environment, as Gymnasium's vector envs take it) in those it marks only;
        the others carry on."""
        super().reset(seed=seed)
        options = dict(options or {})
        if "reset_mask" not in options:
            envs = np.arange(self.num_envs)
            obs = self.task.world.reset(self.task.setups(self.np_random, envs, options))
            self.started = True
        else:
            envs = np.flatnonzero(self._checked_mask(options.pop("reset_mask")))
            obs = self.task.world.restart(envs, self.task.setups(self.np_random, envs, options))
        self.elapsed[envs] = 0
        self.restarting[envs] = False
        return self.task.world.senses, self._info(obs.fixated)

    def step(self, actions):
        """Move every environment one cycle, or restart it if its trial was truncated on the
        step before (its action is then ignored; see the class docstring)."""
        if not self.started:
            raise gymnasium.error.ResetNeeded("call reset before step")
        motor = self.task.motor(actions, (self.num_envs, N_MOTOR))
        restart = np.flatnonzero(self.restarting)
        motor[restart] = STILL
        obs = self.task.world.step(motor)
        if len(restart):
            obs = self.task.world.restart(restart,
                                          self.task.setups(self.np_random, restart, None))
        self.elapsed += 1
        self.elapsed[restart] = 0
        reward = np.array(obs.touch)
        reward[restart] = 0.0
        truncated = self.elapsed >= self.task.cycles
        self.restarting = truncated
        return (self.task.world.senses, reward, np.zeros(self.num_envs, dtype=bool),
                truncated.copy(), self._info(obs.fixated))

    def _checked_mask(self, mask) -> np.ndarray:
        if not self.started:
            raise gymnasium.error.ResetNeeded("reset every environment before resetting some")
        mask = np.asarray(mask)
        if mask.shape != (self.num_envs,) or mask.dtype != np.bool_ or not mask.any():
            raise SetupError(f"reset_mask must be a bool array of shape ({self.num_envs},) "
                             f"with at least one True, got {mask.dtype} {mask.shape}")
        return mask

    def _info(self, fixated: np.ndarray) -> dict:
        return {"fixated": np.array(fixated), "_fixated": np.ones(self.num_envs, dtype=bool)}

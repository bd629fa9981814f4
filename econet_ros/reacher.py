"""A hand-written reaching controller: no network, just vision, proprioception and touch.

It shows what the econet's senses make possible and gives the graph a controller that reaches
from the first generation. Each trial runs through four phases, per environment:

    park    bring the arm to a posture whose hand is out of view (shoulder and elbow fully
            extended: the hand lies 90 degrees right of the gaze), so that whatever vision
            shows afterwards is the object;
    search  turn the eye at full speed until the object appears, then centre it: turn by the
            activation-weighted mean direction of the visual units;
    reach   with the eye held still, place the hand tip on the line of gaze close to the body,
            then extend the elbow while turning the shoulder so the tip moves straight out
            along the gaze (elbow q_e, shoulder q_s = 90 + (180 - q_e) / 2);
    hold    on touch, hold every joint still (equal flexor and extensor activation).

A reach that straightens the arm without touching anything starts over from park.

Vision cannot tell the hand from the object, which is why the arm is parked before looking.
"""
from __future__ import annotations

import numpy as np

from .config import Config
from .controllers import Controller
from .world import N_MOTOR, Observation

PARK, SEARCH, REACH_IN, REACH_OUT, HOLD = range(5)


class HandWrittenReacher(Controller):
    """Reaches for the object with a fixed strategy (see the module docstring)."""

    #: elbow angle of the posture the reach starts from (hand tip near the body, on the gaze)
    START_ELBOW = 30.0
    #: how well centred (degrees) the object must be before the reach starts
    CENTRED_DEG = 1.0

    def __init__(self, n_envs: int, config: Config):
        super().__init__(n_envs, config)
        self.phase = np.full(n_envs, PARK)
        m = config.model
        self._unit_centres = (np.arange(m.visual_units) + 0.5) * (
            m.field_of_view_deg / m.visual_units) - m.field_of_view_deg / 2

    def act(self, obs: Observation) -> np.ndarray:
        m = self.config.model
        if obs.cycle == 0:
            self.phase[:] = PARK
        shoulder = obs.proprio[:, 0] * m.joint_max_deg
        elbow = obs.proprio[:, 2] * m.joint_max_deg
        seen = obs.vision.sum(axis=1)
        direction = (obs.vision @ self._unit_centres) / np.where(seen > 0, seen, 1.0)

        phase = self.phase
        parked = (shoulder >= m.joint_max_deg) & (elbow >= m.joint_max_deg)
        phase[(phase == PARK) & parked] = SEARCH
        centred = (phase == SEARCH) & (seen > 0) & (np.abs(direction) < self.CENTRED_DEG)
        phase[centred] = REACH_IN
        reach_posture = self._gaze_posture(np.full(self.n_envs, self.START_ELBOW))
        at_start = (np.abs(shoulder - reach_posture[0]) < 0.5) & \
            (np.abs(elbow - reach_posture[1]) < 0.5)
        phase[(phase == REACH_IN) & at_start] = REACH_OUT
        phase[(phase == REACH_OUT) & (elbow >= m.joint_max_deg)] = PARK   # missed: look again
        phase[obs.touch > 0.5] = HOLD

        target_shoulder, target_elbow = shoulder.copy(), elbow.copy()
        target_shoulder[phase == PARK] = m.joint_max_deg
        target_elbow[phase == PARK] = m.joint_max_deg
        inward = phase == REACH_IN
        target_shoulder[inward], target_elbow[inward] = reach_posture[0][inward], \
            reach_posture[1][inward]
        outward = phase == REACH_OUT
        next_elbow = np.minimum(elbow + m.max_rotation_deg, m.joint_max_deg)
        target_shoulder[outward], target_elbow[outward] = \
            self._gaze_posture(next_elbow)[0][outward], next_elbow[outward]

        turn = np.zeros(self.n_envs)
        searching = phase == SEARCH
        turn[searching] = np.where(seen[searching] > 0, direction[searching],
                                   m.max_rotation_deg)
        motor = np.empty((self.n_envs, N_MOTOR))
        motor[:, 0] = 0.5 + np.clip(turn / (2 * m.max_rotation_deg), -0.5, 0.5)
        motor[:, 1:3] = self._joint_command(target_shoulder - shoulder)
        motor[:, 3:5] = self._joint_command(target_elbow - elbow)
        return motor

    def _gaze_posture(self, elbow: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Shoulder and elbow angles that put the hand tip on the line of gaze."""
        return 90.0 + (180.0 - elbow) / 2.0, elbow

    def _joint_command(self, change: np.ndarray) -> np.ndarray:
        """(flexor, extensor) activations that change a joint angle by ``change`` degrees,
        as far as one cycle allows (a joint moves by -15 * (flexor - extensor))."""
        half = np.clip(change / (2 * self.config.model.max_rotation_deg), -0.5, 0.5)
        return np.stack([0.5 - half, 0.5 + half], axis=1)

"""Pictures of a trial: an animated GIF and a PNG filmstrip of the workspace, the arm, the eye's
field of view, the object, and contact."""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.animation import FuncAnimation, PillowWriter  # noqa: E402
from matplotlib.patches import Circle, Wedge  # noqa: E402
import numpy as np  # noqa: E402

from ..config import ModelConfig  # noqa: E402
from ..trials import Trace  # noqa: E402
from ..world import Geometry, _arm_points_batch  # noqa: E402


@dataclass
class TrialFrames:
    """One environment's trial, state by state (row t = after t cycles)."""

    body: np.ndarray        # (C+1,) degrees
    shoulder: np.ndarray    # (C+1,)
    elbow: np.ndarray       # (C+1,)
    touch: np.ndarray       # (C+1,) bool
    object_xy: np.ndarray   # (2,)

    @classmethod
    def from_trace(cls, trace: Trace, env: int) -> "TrialFrames":
        return cls(trace.body[:, env], trace.shoulder[:, env], trace.elbow[:, env],
                   trace.touch[:, env], trace.object_xy[env])

    def __len__(self) -> int:
        return len(self.body)


class _Scene:
    """The artists of one panel, updated frame by frame."""

    def __init__(self, ax, frames: TrialFrames, model: ModelConfig):
        self.frames, self.model = frames, model
        self.points = _arm_points_batch(frames.body, frames.shoulder, frames.elbow,
                                        Geometry.of(model))
        half = model.workspace_size / 2
        ax.set_xlim(-half, half)
        ax.set_ylim(-half, half)
        ax.set_aspect("equal")
        ax.set_xticks([])
        ax.set_yticks([])
        self.field = Wedge((0, 0), model.visual_range, 0, 1, color="gold", alpha=0.25)
        ax.add_patch(self.field)
        self.object = Circle(frames.object_xy, model.object_radius, color="tab:blue")
        ax.add_patch(self.object)
        (self.arm,) = ax.plot([], [], color="0.3", lw=3, solid_capstyle="round")
        (self.hand,) = ax.plot([], [], color="tab:orange", lw=5, solid_capstyle="round")
        ax.plot([0], [0], "ko", ms=5)
        self.label = ax.set_title("")

    def show(self, t: int, cycle: int | None = None):
        """Draw state t, labelled as cycle ``cycle`` (default t)."""
        half_fov = self.model.field_of_view_deg / 2
        body = self.frames.body[t]
        self.field.set_theta1(body - half_fov)
        self.field.set_theta2(body + half_fov)
        p = self.points[t]
        self.arm.set_data(p[:3, 0], p[:3, 1])
        self.hand.set_data(p[2:, 0], p[2:, 1])
        touching = bool(self.frames.touch[t])
        self.object.set_color("tab:red" if touching else "tab:blue")
        self.label.set_text(f"cycle {t if cycle is None else cycle}"
                            + (" - contact" if touching else ""))
        return self.field, self.arm, self.hand, self.object, self.label


def animate(frames: TrialFrames, model: ModelConfig, path: Path, fps: int = 10) -> Path:
    """Write the trial as an animated GIF."""
    fig, ax = plt.subplots(figsize=(4, 4), dpi=80)
    scene = _Scene(ax, frames, model)
    animation = FuncAnimation(fig, scene.show, frames=len(frames), blit=False)
    animation.save(str(path), writer=PillowWriter(fps=fps))
    plt.close(fig)
    return Path(path)


def rgb_image(frames: TrialFrames, model: ModelConfig, t: int, cycle: int) -> np.ndarray:
    """State t as an RGB image (320, 320, 3) of uint8, labelled as cycle ``cycle`` (for
    Gymnasium's rgb_array render mode)."""
    fig, ax = plt.subplots(figsize=(4, 4), dpi=80)
    _Scene(ax, frames, model).show(t, cycle)
    fig.canvas.draw()
    image = np.array(fig.canvas.buffer_rgba())[..., :3]
    plt.close(fig)
    return image


def filmstrip(frames: TrialFrames, model: ModelConfig, path: Path, panels: int = 10) -> Path:
    """Write a PNG of evenly spaced moments of the trial, first cycle to last."""
    times = np.unique(np.linspace(0, len(frames) - 1, panels).round().astype(int))
    columns = min(len(times), 5)
    rows = math.ceil(len(times) / columns)
    fig, axes = plt.subplots(rows, columns, figsize=(2.6 * columns, 2.8 * rows), dpi=80,
                             squeeze=False)
    for ax, t in zip(axes.flat, times):
        _Scene(ax, frames, model).show(int(t))
    for ax in axes.flat[len(times):]:
        ax.axis("off")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return Path(path)

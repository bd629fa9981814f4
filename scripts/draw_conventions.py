"""Draw docs/figures/shoulder_conventions.png: the two readings of the shoulder's 180-degree
range (config model.shoulder_convention), each with the straight arm at q_s = 0, 45, 90, 135, 180
and the eye's field, computed by the model's own kinematics (econet_ros.world)."""
from __future__ import annotations

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import Wedge  # noqa: E402
import numpy as np  # noqa: E402

from econet_ros.config import ModelConfig  # noqa: E402
from econet_ros.world import World  # noqa: E402

OUT = Path(__file__).resolve().parents[1] / "docs" / "figures" / "shoulder_conventions.png"
ANGLES = (0.0, 45.0, 90.0, 135.0, 180.0)


def draw(ax, convention: str) -> None:
    model = ModelConfig(shoulder_convention=convention)
    world = World(len(ANGLES), model)
    world.shoulder[:] = ANGLES
    world.elbow[:] = 180.0
    world.refresh()
    half = model.field_of_view_deg / 2
    ax.add_patch(Wedge((0, 0), 50, -half, half, color="gold", alpha=0.3))
    ax.annotate("", (55, 0), (0, 0), arrowprops=dict(arrowstyle="->", color="0.4"))
    ax.text(52, -7, "gaze", color="0.4", fontsize=8)
    shades = plt.cm.viridis(np.linspace(0.1, 0.9, len(ANGLES)))
    for points, angle, shade in zip(world.arm_points(), ANGLES, shades):
        ax.plot(points[:3, 0], points[:3, 1], color=shade, lw=2)
        ax.plot(points[2:, 0], points[2:, 1], color=shade, lw=5)
        ax.text(*(points[3] * 1.08), f"q_s={angle:.0f}", color=shade, fontsize=8,
                ha="center", va="center")
    ax.plot(0, 0, "ko")
    ax.set_xlim(-62, 70)
    ax.set_ylim(-62, 62)
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_yticks([])
    extended = "90 degrees right of the gaze" if convention == "centred" else "along the gaze"
    ax.set_title(f"'{convention}': extended (q_s = 180) points {extended}", fontsize=9)


def main() -> int:
    fig, axes = plt.subplots(1, 2, figsize=(9, 4.6), dpi=90)
    for ax, convention in zip(axes, ("centred", "forward")):
        draw(ax, convention)
    fig.suptitle("The shoulder's 0-180 degree range, straight arm (q_e = 180); flexing (lower "
                 "q_s) turns left", fontsize=10)
    fig.tight_layout()
    fig.savefig(OUT)
    print(OUT)
    return 0


if __name__ == "__main__":
    sys.exit(main())

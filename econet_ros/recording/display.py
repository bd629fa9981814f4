"""The pictures the graph shows, as serialized ROS 2 messages built without ROS: joint_states
and markers of one environment, and the /tf_static that places the `econet` frame, so that the
world node (which publishes these bytes as they are), ``econet evaluate --record`` and the
viewer all send the same messages; and which of a world's cycles get a picture (PictureClock).

Frame and units: the agent sits at the origin of the `econet` frame, x to the right, y up, z
out of the workspace plane; one workspace unit is one metre on screen (the paper's workspace is
100 x 100 units, the arm's two segments 25 each). /tf_static places `econet` at the origin of
`map`, RViz's default fixed frame, so RViz and Foxglove open without typing a frame.
"""
from __future__ import annotations

import math

import numpy as np

from ..config import ModelConfig
from ..topics import TF_STATIC
from .messages import message, serialize

PARENT_FRAME = "map"
JOINTS = ("body", "shoulder", "elbow")
# Marker.type values (visualization_msgs/Marker)
LINE_STRIP, LINE_LIST, CYLINDER = 4, 5, 3


class PictureClock:
    """Which cycles get a picture. A world at a fixed rate whose rate the display rate divides
    (free mode at 20 cycles/s shows 20, 10, 5 ... pictures a second) pictures every k-th cycle:
    an even picture rate, all 20 of 20 cycles when the rates match, where a wall-clock throttle
    drops every cycle whose timer fired a little early. A display rate at or above the world's
    (or 0) pictures every cycle. Otherwise (lockstep, whose pace is the controller's, or rates
    that do not divide) at most one picture per display period by the wall clock. A trial's
    first and last cycles always get one."""

    def __init__(self, display_rate_hz: float, world_rate_hz: float | None = None):
        self.every = cycles_per_picture(display_rate_hz, world_rate_hz)
        self.period = 1.0 / display_rate_hz if display_rate_hz > 0 else 0.0
        self.last = -math.inf

    def restart(self) -> None:
        """A new trial: its cycle 0 gets a picture."""
        self.last = -math.inf

    def due(self, cycle: int, final: bool, now: float) -> bool:
        """Whether `cycle` (`final`: the trial's last) gets a picture, at monotonic time `now`."""
        if self.every is not None:
            return final or cycle % self.every == 0
        if final or now - self.last >= self.period:
            self.last = now
            return True
        return False


def cycles_per_picture(display_rate_hz: float, world_rate_hz: float | None) -> int | None:
    """k such that every k-th cycle of a world at `world_rate_hz` makes `display_rate_hz`
    (1: every cycle), or None where no whole k does or the world has no fixed rate (None)."""
    if display_rate_hz <= 0:
        return 1
    if world_rate_hz is None:
        return None
    if display_rate_hz >= world_rate_hz:
        return 1
    k = round(world_rate_hz / display_rate_hz)
    return k if math.isclose(k * display_rate_hz, world_rate_hz, rel_tol=1e-9) else None


def _header(frame_id: str, stamp_ns: int):
    stamp = message("builtin_interfaces/msg/Time", sec=stamp_ns // 10 ** 9,
                    nanosec=stamp_ns % 10 ** 9)
    return message("std_msgs/msg/Header", stamp=stamp, frame_id=frame_id)


def picture(world, env: int, touching: bool, fixated: bool, frame_id: str,
            stamp_ns: int) -> dict[str, bytes]:
    """joint_states and markers of environment `env` of a World, serialized: the arm, the hand
    (green while touching), the eye's field (blue while fixating) and the object."""
    model: ModelConfig = world.model
    header = _header(frame_id, stamp_ns)
    angles = [math.radians(float(a[env])) for a in (world.body, world.shoulder, world.elbow)]
    joints = message("sensor_msgs/msg/JointState", header=header, name=list(JOINTS),
                     position=np.array(angles))
    points = world.arm_points(slice(env, env + 1))[0]
    body, half, reach = angles[0], math.radians(model.field_of_view_deg / 2), model.visual_range
    eye_field = [(0.0, 0.0), (reach * math.cos(body - half), reach * math.sin(body - half)),
                 (0.0, 0.0), (reach * math.cos(body + half), reach * math.sin(body + half))]
    markers = [
        _marker(header, 0, "arm", LINE_STRIP, points[:3], (0.9, 0.8, 0.6), 1.5),
        _marker(header, 1, "hand", LINE_STRIP, points[2:],
                (0.1, 0.9, 0.1) if touching else (0.9, 0.3, 0.2), 2.0),
        _marker(header, 2, "eye_field", LINE_LIST, eye_field,
                (0.3, 0.6, 1.0) if fixated else (0.5, 0.5, 0.5), 0.4),
        _marker(header, 3, "object", CYLINDER, [world.object_xy[env]], (1.0, 0.8, 0.0),
                2 * model.object_radius),
    ]
    return {"joint_states": serialize(joints, "sensor_msgs/msg/JointState"),
            "markers": serialize(message("visualization_msgs/msg/MarkerArray", markers=markers),
                                 "visualization_msgs/msg/MarkerArray")}


def _marker(header, ident, ns, kind, xy, rgb, size):
    color = message("std_msgs/msg/ColorRGBA", r=rgb[0], g=rgb[1], b=rgb[2], a=1.0)
    orientation = message("geometry_msgs/msg/Quaternion", w=1.0)
    if kind == CYLINDER:
        position = message("geometry_msgs/msg/Point", x=float(xy[0][0]), y=float(xy[0][1]))
        return message("visualization_msgs/msg/Marker", header=header, ns=ns, id=ident,
                       type=kind, pose=message("geometry_msgs/msg/Pose", position=position,
                                               orientation=orientation),
                       scale=message("geometry_msgs/msg/Vector3", x=float(size), y=float(size),
                                     z=1.0), color=color)
    return message("visualization_msgs/msg/Marker", header=header, ns=ns, id=ident, type=kind,
                   pose=message("geometry_msgs/msg/Pose", orientation=orientation),
                   scale=message("geometry_msgs/msg/Vector3", x=float(size)), color=color,
                   points=[message("geometry_msgs/msg/Point", x=float(x), y=float(y))
                           for x, y in xy])


def tf_static(frame_id: str, stamp_ns: int) -> bytes:
    """The /tf_static message that puts `frame_id` at the origin of PARENT_FRAME."""
    transform = message("geometry_msgs/msg/TransformStamped",
                        header=_header(PARENT_FRAME, stamp_ns), child_frame_id=frame_id,
                        transform=message("geometry_msgs/msg/Transform",
                                          rotation=message("geometry_msgs/msg/Quaternion",
                                                           w=1.0)))
    return serialize(message(TF_STATIC.type, transforms=[transform]), TF_STATIC.type)


def frame_of(topic: str, data: bytes) -> str:
    """The frame_id of a serialized joint_states or markers message, read in place: after the
    4-byte CDR header (and a MarkerArray's marker count) comes the header's 8-byte stamp, then
    the frame as a length and NUL-terminated text."""
    at = 12 if topic == "joint_states" else 16
    length = int.from_bytes(data[at:at + 4], "little")
    return bytes(data[at + 4:at + 3 + length]).decode("utf-8")

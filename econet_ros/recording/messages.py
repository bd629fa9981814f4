"""ROS 2 messages without ROS: a rosbags typestore with ROS 2 Kilted's standard types and
econet_msgs, and a constructor that fills every field not given with its default, as a ROS
message class does (rosbags' classes want every field)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

ECONET_TYPES = ("TrialStart", "Retina", "Proprioception", "Touch", "MuscleCommand")


def msg_dir() -> Path:
    """The folder holding econet_msgs' .msg definitions: the source tree's, else the copy that
    setup.py installs beside this module (so a pip install without ROS reads bags too)."""
    here = Path(__file__).resolve().parents[2] / "econet_msgs" / "msg"
    return here if here.is_dir() else Path(__file__).resolve().parent / "msg"


_TYPESTORE = None


def typestore():
    """A rosbags typestore with ROS 2 Kilted's standard types and econet_msgs registered."""
    global _TYPESTORE
    if _TYPESTORE is None:
        from rosbags.typesys import Stores, get_types_from_msg, get_typestore

        store = get_typestore(Stores.ROS2_KILTED)
        types = {}
        for name in ECONET_TYPES:
            text = (msg_dir() / f"{name}.msg").read_text(encoding="utf-8")
            types.update(get_types_from_msg(text, f"econet_msgs/msg/{name}"))
        store.register(types)
        _TYPESTORE = store
    return _TYPESTORE


_NUMBERS = {"bool": np.bool_, "byte": np.uint8, "char": np.uint8, "int8": np.int8,
            "uint8": np.uint8, "int16": np.int16, "uint16": np.uint16, "int32": np.int32,
            "uint32": np.uint32, "int64": np.int64, "uint64": np.uint64, "float32": np.float32,
            "float64": np.float64}


_DEFAULTS: dict[str, tuple[type, dict]] = {}     # type -> (class, default field values)


def message(typename: str, **fields):
    """A rosbags message of `typename` with every field not given at its default (zero, empty),
    as a ROS message constructor would make it. The default values are made once per type and
    shared (a picture is built many times a second): treat messages as read-only."""
    known = _DEFAULTS.get(typename)
    if known is None:
        store = typestore()
        known = _DEFAULTS[typename] = (store.types[typename], {
            name: _default(node) for name, node in store.fielddefs[typename][1]})
    cls, defaults = known
    return cls(**{**defaults, **fields})


def _default(node):
    from rosbags.interfaces import Nodetype

    kind, detail = node
    if kind == Nodetype.NAME:
        return message(detail)
    if kind == Nodetype.BASE:
        return "" if detail[0] in ("string", "wstring") else \
            _NUMBERS[detail[0]](0).item() if detail[0] != "bool" else False
    inner, size = detail
    number = inner[0] == Nodetype.BASE and inner[1][0] in _NUMBERS
    length = size if kind == Nodetype.ARRAY else 0
    if number:
        return np.zeros(length, dtype=_NUMBERS[inner[1][0]])
    return [_default(inner) for _ in range(length)]


def serialize(msg, typename: str) -> bytes:
    return bytes(typestore().serialize_cdr(msg, typename))



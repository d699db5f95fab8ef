"""The sandbox's LCM messages in Python: decoded by lcm-gen's Python types
(generated at build time into sandbox/sandbox_msgs/, pure Python), their
arrays as numpy, and the input messages encoded from Python values."""

import math

import numpy as np

from . import sandbox_msgs

# Every message type, by its name and by its fingerprint (the first 8 bytes).
message_types = {name: getattr(sandbox_msgs, name) for name in dir(sandbox_msgs)
                 if name.endswith("_t")}
_BY_FINGERPRINT = {cls._get_packed_fingerprint(): cls for cls in message_types.values()}


def _converted(value):
    """A numeric array as numpy, a string array as a list, a scalar as it is."""
    if value.__class__ is tuple or value.__class__ is list:
        return list(value) if value and value[0].__class__ is str else np.array(value)
    return value


class Message:
    """A decoded message: its fields as attributes (as in bridge/lcmtypes/*.lcm,
    flat), numeric arrays as numpy arrays, string arrays as lists, each made
    when first read; `lcm_type` is the type's name, `fields()` all of them."""

    def __init__(self, lcm_type, raw):
        self.__dict__["lcm_type"] = lcm_type
        self.__dict__["_raw"] = raw

    def __getattr__(self, name):  # a field not read before
        raw = self.__dict__["_raw"]
        if name.startswith("_") or name not in raw.__slots__:
            raise AttributeError(f"{self.lcm_type} has no field {name!r}; it has "
                                 f"{', '.join(raw.__slots__)}")
        value = self.__dict__[name] = _converted(getattr(raw, name))
        return value

    def fields(self):
        """{field: value} of every field, in the type's order."""
        return {name: getattr(self, name) for name in self._raw.__slots__}

    def __dir__(self):
        return ["lcm_type", "fields", *self._raw.__slots__]

    def __repr__(self):
        shown = ", ".join(f"{name}={value!r}" for name, value in self.fields().items())
        return f"{self.lcm_type}({shown})"


def decode(data):
    """The message in `data` (bytes, or any bytes-like object) as a `Message`;
    ValueError when its fingerprint is not a sandbox type or it does not decode."""
    if data.__class__ is not bytes:
        data = bytes(data)
    cls = _BY_FINGERPRINT.get(data[:8])
    if cls is None:
        raise ValueError(f"not a sandbox message (fingerprint {data[:8].hex() or 'missing'})")
    try:
        raw = cls.decode(data)
    except Exception as error:  # struct.error on a short message
        raise ValueError(f"{cls.__name__} does not decode: {error}") from None
    return Message(cls.__name__, raw)


def finite(value, count, argument):
    """`value` as `count` finite floats (a tuple), else ValueError naming `argument`."""
    try:
        if isinstance(value, (tuple, list)):  # the common case, without numpy
            kinds = set(map(type, value))
            if str in kinds or bytes in kinds:  # float() would read "1.5"
                raise TypeError
            values = tuple(map(float, value))
        else:
            values = tuple(np.asarray(value, dtype=np.float64).reshape(-1).tolist())
    except (TypeError, ValueError, OverflowError):
        raise ValueError(f"{argument} must be {count or 'some'} numbers, got {value!r}") from None
    if count is not None and len(values) != count:
        raise ValueError(f"{argument} must be {count} numbers, got {len(values)}")
    if not all(map(math.isfinite, values)):
        raise ValueError(f"{argument} must be finite, got {value!r}")
    return values


def utime_of(value):
    """`value` as microseconds that fit LCM's int64, else ValueError."""
    try:
        utime = int(value)
    except (TypeError, ValueError, OverflowError):
        raise ValueError(f"utime must be whole microseconds, got {value!r}") from None
    if not -2**63 <= utime < 2**63:
        raise ValueError(f"utime must fit in 64 bits, got {utime}")
    return utime


def pose_message(position, orientation, utime, seq):
    message = sandbox_msgs.robot_pose_t()
    message.utime, message.seq = int(utime), int(seq)
    message.position = finite(position, 3, "position")
    message.orientation = finite(orientation, 4, "orientation")
    norm = math.sqrt(sum(v * v for v in message.orientation))
    if abs(norm - 1.0) > 1e-6:
        raise ValueError(f"orientation must be a unit quaternion (w, x, y, z), its norm is {norm}")
    return message.encode()


def bones_message(values, utime, seq):
    message = sandbox_msgs.bone_values_t()
    message.utime, message.seq = int(utime), int(seq)
    message.values = finite(values, None, "bones")
    message.num_values = len(message.values)
    return message.encode()


def joints_message(values, utime, seq):
    """`values`: {joint name: value}, or every joint's value in the robot's order."""
    message = sandbox_msgs.joint_values_t()
    message.utime, message.seq = int(utime), int(seq)
    if isinstance(values, dict):
        names = list(values)
        if not all(isinstance(name, str) for name in names):
            raise ValueError("joints: names must be strings")
        message.names = names
        message.values = finite([values[name] for name in names], len(names), "joints")
    else:
        message.names = []
        message.values = finite(values, None, "joints")
    message.num_names, message.num_values = len(message.names), len(message.values)
    return message.encode()


def actors_message(placements, utime, seq):
    """`placements`: {actor name: (position, orientation)}."""
    if not isinstance(placements, dict):
        raise ValueError("actors must be a dict {name: (position, orientation)}")
    message = sandbox_msgs.actor_placements_t()
    message.utime, message.seq = int(utime), int(seq)
    message.names, positions, orientations = [], [], []
    for name, placement in placements.items():
        if not isinstance(name, str):
            raise ValueError("actors: names must be strings")
        try:
            position, orientation = placement
        except (TypeError, ValueError):
            raise ValueError(f"actors[{name!r}] must be (position, orientation)") from None
        message.names.append(name)
        positions += finite(position, 3, f"actors[{name!r}] position")
        orientations += finite(orientation, 4, f"actors[{name!r}] orientation")
    message.positions, message.orientations = positions, orientations
    message.num_actors = len(message.names)
    message.num_positions, message.num_orientations = len(positions), len(orientations)
    return message.encode()

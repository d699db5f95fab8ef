"""The sandbox's LCM messages in Python: decoded in C++ (`_sandbox._decode`:
lcm-gen's C++ types; a field becomes a Python value, an array a numpy array,
when first read), and the
input messages encoded from Python values by lcm-gen's Python types
(generated at build time into sandbox/sandbox_msgs/, pure Python)."""

import math

import numpy as np

from . import _sandbox, sandbox_msgs

# Every message type, by its name.
message_types = {name: getattr(sandbox_msgs, name) for name in dir(sandbox_msgs)
                 if name.endswith("_t")}


Message = _sandbox.Message


def decode(data):
    """The message in `data` (bytes, or any bytes-like object) as a `Message`;
    ValueError when it is not exactly one message of a sandbox type (naming
    the type and the field that does not fit)."""
    return _sandbox._decode(data)


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


def names_of(names, argument):
    """`names` as a list of strings an LCM string carries (no NUL: it ends one), else ValueError."""
    names = list(names)
    if not all(isinstance(name, str) and "\0" not in name for name in names):
        raise ValueError(f"{argument}: names must be strings without NUL")
    return names


def joints_message(values, utime, seq):
    """`values`: {joint name: value}, or every joint's value in the robot's order."""
    message = sandbox_msgs.joint_values_t()
    message.utime, message.seq = int(utime), int(seq)
    if isinstance(values, dict):
        names = names_of(values, "joints")
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
    names_of(placements, "actors")
    for name, placement in placements.items():
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

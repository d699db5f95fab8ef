"""sandbox.decode (lcm-gen's C++ types, in the extension) against lcm-gen's
Python types, an independent encoder and decoder: every message type of
bridge/lcmtypes filled with values hypothesis draws, and every message a
lock-step run publishes, read field by field the same."""
import pathlib
import re

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

import sandbox

TYPES_DIR = pathlib.Path(__file__).resolve().parents[2] / "bridge/lcmtypes"
# LCM's primitive types: (numpy dtype, strategy).
PRIMITIVES = {
    "int8_t": (np.int8, st.integers(-2**7, 2**7 - 1)),
    "int16_t": (np.int16, st.integers(-2**15, 2**15 - 1)),
    "int32_t": (np.int32, st.integers(-2**31, 2**31 - 1)),
    "int64_t": (np.int64, st.integers(-2**63, 2**63 - 1)),
    "float": (np.float32, st.floats(width=32)),
    "double": (np.float64, st.floats()),
    "string": (None, st.text(st.characters(blacklist_categories=("Cs",), blacklist_characters="\0"),
                             max_size=12)),
}


def declared_fields(lcm_type):
    """[(type, name, dimension or None)] from the .lcm file's text."""
    text = re.sub(r"//[^\n]*", "", (TYPES_DIR / f"{lcm_type}.lcm").read_text())
    body = text[text.index("{") + 1:text.rindex("}")]
    return [(kind, name, dimension or None) for kind, name, dimension in
            re.findall(r"(\w+)\s+(\w+)\s*(?:\[\s*(\w+)\s*\])?\s*;", body)]


@st.composite
def filled(draw, lcm_type):
    """An lcm-gen Python message of `lcm_type`, every field drawn."""
    message = sandbox.message_types[lcm_type]()
    counts = {}
    for kind, name, dimension in declared_fields(lcm_type):
        strategy = PRIMITIVES[kind][1]
        if dimension is None:
            value = draw(strategy)
            if name.startswith("num_") or name in ("steps",):  # a count: kept small
                value = draw(st.integers(0, 6))
            counts[name] = value
        else:
            length = int(dimension) if dimension.isdigit() else counts[dimension]
            value = draw(st.lists(strategy, min_size=length, max_size=length))
        setattr(message, name, value)
    return message


def same(decoded, expected, kind, dimension):
    """A decoded field as lcm-gen's Python types have it: a string array as a
    list, a numeric one as a numpy array of the declared dtype, equal values
    (NaN as NaN), a number as int or float."""
    if dimension is not None and kind == "string":
        return decoded == list(expected)
    if dimension is not None:
        return (isinstance(decoded, np.ndarray) and decoded.dtype == PRIMITIVES[kind][0] and
                decoded.shape == (len(expected),) and
                np.array_equal(decoded, np.array(expected, dtype=decoded.dtype), equal_nan=True))
    if isinstance(expected, float) and expected != expected:
        return isinstance(decoded, float) and decoded != decoded
    return decoded == expected and type(decoded) is type(expected)


def check(data):
    """decode(data) and lcm-gen's Python decoder agree on every field."""
    message = sandbox.decode(data)
    reference = sandbox.message_types[message.lcm_type].decode(bytes(data))
    assert list(message.fields()) == list(reference.__slots__)
    for kind, name, dimension in declared_fields(message.lcm_type):
        assert same(getattr(message, name), getattr(reference, name), kind, dimension), \
            (message.lcm_type, name)
    return message


@settings(max_examples=400, deadline=None, database=None)
@given(st.sampled_from(sorted(sandbox.message_types)).flatmap(filled))
def test_every_type_decodes_as_lcm_gens_python_types_read_it(message):
    check(message.encode())


def test_every_message_of_a_lockstep_run_decodes_the_same():
    """The sample level, and the bundled robots (a ground scanner, a lidar)."""
    seen = set()
    robots = pathlib.Path(__file__).resolve().parents[2] / "assets/robots/robots.toml"
    for level, ticks in ((None, 3), (robots, 12)):
        with sandbox.Lockstep(level) as run:
            for k in range(ticks):
                outputs = run.step(poses={robot: ((5.0 * k, 0.0, 40.0), (1.0, 0.0, 0.0, 0.0))
                                          for robot in run.robots})
                for channel in outputs:
                    for data in outputs.raw(channel):
                        seen.add(check(data).lcm_type)
    assert {"robot_state_t", "scan_face_t", "range_t", "status_t", "surface_table_t",
            "ground_map_t", "lidar_scan_t"} <= seen, seen


def test_a_field_that_is_not_there_names_the_fields():
    message = sandbox.decode(sandbox.messages.pose_message((1, 2, 3), (1, 0, 0, 0), 5, 7))
    assert message.lcm_type == "robot_pose_t" and message.utime == 5 and message.seq == 7
    assert message.position.tolist() == [1.0, 2.0, 3.0]
    try:
        message.velocity
    except AttributeError as error:
        assert "robot_pose_t has no field 'velocity'; it has utime, seq, position" in str(error)
    else:
        raise AssertionError("no AttributeError")
    assert dir(message) == sorted(["lcm_type", "fields", "utime", "seq", "position",
                                   "orientation"])

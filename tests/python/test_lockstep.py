"""Lockstep.step() against `sandbox run --replay`, and read_log.

The same inputs (poses along a climbing turn, bending bones) go to the program
as an LCM log written here (the file format restated from lcm-logger's, not
the project's writer) and to Lockstep.step(); each tick's outputs must equal
the replay's recorded outputs message for message, and the two recordings must
be the same bytes. read_log is checked against the inputs written here.
"""
import math
import os
import struct
import subprocess

import numpy as np
import pytest

import sandbox
from sandbox import sandbox_msgs

SANDBOX = os.environ.get("SANDBOX", "sandbox")
TICKS = 40
BONES = len(sandbox.World().bones("ELAHA"))


def write_log(path, events):
    """An LCM log: per event the sync word, number, utime, channel and data lengths."""
    with open(path, "wb") as f:
        for number, (utime, channel, data) in enumerate(events):
            f.write(struct.pack(">IqqII", 0xEDA1DA01, number, utime, len(channel), len(data)))
            f.write(channel.encode() + data)


def inputs():
    """(utime, position, orientation, bone values) a tick."""
    for k in range(TICKS):
        heading = 0.05 * k
        q = (math.cos(heading / 2), 0.0, 0.0, math.sin(heading / 2))
        bend = [0.01 * k * math.sin(0.3 * b) for b in range(BONES)]
        yield 1_000_000 + 10_000 * k, (3.0 * k, -100.0 + 2.0 * k, 40.0 + 0.5 * k), q, bend


def encoded_inputs():
    events = []
    for k, (utime, position, q, bend) in enumerate(inputs()):
        bones = sandbox_msgs.bone_values_t()
        bones.utime, bones.seq, bones.num_values, bones.values = utime, k, len(bend), bend
        pose = sandbox_msgs.robot_pose_t()
        pose.utime, pose.seq, pose.position, pose.orientation = utime, k, position, q
        events += [(utime, "ELAHA/BONES", bones.encode()), (utime, "ELAHA/POSE", pose.encode())]
    return events


def same(a, b):
    assert a.lcm_type == b.lcm_type
    assert a.fields().keys() == b.fields().keys()
    for field, value in a.fields().items():
        other = getattr(b, field)
        if isinstance(value, np.ndarray):
            assert np.array_equal(value, other, equal_nan=True), field
        else:
            assert value == other, field


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    folder = tmp_path_factory.mktemp("lockstep")
    write_log(folder / "inputs.lcmlog", encoded_inputs())
    subprocess.run([SANDBOX, "run", "--replay", str(folder / "inputs.lcmlog"), "--record",
                    str(folder / "replay.lcmlog")], check=True, stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL)
    steps = []
    with sandbox.Lockstep(args=["--record", str(folder / "step.lcmlog")]) as run:
        for utime, position, q, bend in inputs():
            steps.append(run.step(poses={"ELAHA": (position, q)}, bones={"ELAHA": bend},
                                  utime=utime))
    assert "40 ticks" in run.summary
    return folder, steps


def test_each_step_equals_the_replays_tick(runs):
    folder, steps = runs
    replay = sandbox.read_log(folder / "replay.lcmlog")
    assert replay.stopped_early == "" and not replay.undecoded
    stepped = {}
    for k, outputs in enumerate(steps):
        assert outputs.tick == k
        for channel, messages in outputs.items():
            stepped.setdefault(channel, []).extend(messages)
    assert sorted(stepped) == sorted(replay.channels)
    assert len(stepped["ELAHA/STATE"]) == TICKS and len(stepped["ELAHA/SCAN_FACE"]) > 0
    for channel, messages in stepped.items():
        assert len(messages) == len(replay[channel]), channel
        for mine, theirs in zip(messages, replay[channel].messages):
            same(mine, theirs)
    assert (folder / "step.lcmlog").read_bytes() == (folder / "replay.lcmlog").read_bytes()


def test_state_is_the_pose_and_bones_given(runs):
    _, steps = runs
    for outputs, (utime, position, q, bend) in zip(steps, inputs()):
        state = outputs["ELAHA/STATE"][0]
        assert state.utime == utime
        assert np.allclose(state.position, position, atol=1e-9)
        assert np.allclose(state.orientation, q, atol=1e-12)
        assert np.allclose(state.bone_values, bend, atol=1e-12)


def test_read_log_gives_the_inputs_written(runs):
    folder, _ = runs
    log = sandbox.read_log(folder / "inputs.lcmlog", channels=["ELAHA/POSE"])
    assert list(log.channels) == ["ELAHA/POSE"] and log.events == 2 * TICKS
    poses = log["ELAHA/POSE"]
    expected = list(inputs())
    assert poses.lcm_type == "robot_pose_t" and len(poses) == TICKS
    assert np.array_equal(poses.utime, [e[0] for e in expected])
    assert np.array_equal(poses.array("position"), [e[1] for e in expected])
    assert poses.array("orientation").shape == (TICKS, 4)
    with pytest.raises(KeyError, match="position"):
        poses.array("altitude")
    with pytest.raises(KeyError, match="ELAHA/POSE"):
        log["ELAHA/STATE"]


def test_a_log_cut_short_is_read_to_the_break(runs, tmp_path):
    folder, _ = runs
    data = (folder / "inputs.lcmlog").read_bytes()
    cut = tmp_path / "cut.lcmlog"
    cut.write_bytes(data[: len(data) - 7])
    log = sandbox.read_log(cut)
    assert "truncated" in log.stopped_early
    assert len(log["ELAHA/POSE"]) == TICKS - 1 and len(log["ELAHA/BONES"]) == TICKS


def test_a_file_that_is_not_a_log_is_an_error_naming_it(tmp_path):
    bad = tmp_path / "notes.txt"
    bad.write_text("not a log\n" * 10)
    with pytest.raises(RuntimeError, match="notes.txt"):
        sandbox.read_log(bad)


def test_bad_steps_say_what_is_wrong():
    with sandbox.Lockstep(args=["--no-sensors"]) as run:
        with pytest.raises(ValueError, match="first step needs a pose"):
            run.step()
        with pytest.raises(KeyError, match="ELAHA"):
            run.step(poses={"NOBODY": (0, 0, 0)})
        with pytest.raises(ValueError, match="orientation"):
            run.step(poses={"ELAHA": ((0, 0, 10), (1, 1, 0, 0))})
        with pytest.raises(ValueError, match="position"):
            run.step(poses={"ELAHA": ((0, float("nan"), 10), (1, 0, 0, 0))})
        assert run.step(poses={"ELAHA": (0, 0, 10)}).tick == 0
        # A bone count the robot does not have: the program rejects the message, the tick runs.
        outputs = run.step(bones={"ELAHA": [0.1] * (BONES + 3)})
        assert outputs.tick == 1 and "ELAHA/BONES" in run.messages
        # A pose the program refuses (cut short): no tick, the program's reason said.
        pose = sandbox_msgs.robot_pose_t()
        pose.utime, pose.seq, pose.orientation = 3_000_000, 9, (1.0, 0.0, 0.0, 0.0)
        with pytest.raises(ValueError, match="no robot a pose(.|\n)*ELAHA/POSE"):
            run._run.step([("ELAHA/POSE", pose.encode()[:-8])])
        assert run.step().tick == 2  # the last pose again, a period later
    with pytest.raises(ValueError, match="--replay"):
        sandbox.Lockstep(args=["--replay", "x.lcmlog"])
    with pytest.raises(ValueError, match="--rate"):
        sandbox.Lockstep(args=["--rate", "fast"])
    with pytest.raises(sandbox.LevelError, match="missing.toml"):
        sandbox.Lockstep("missing.toml")


def frames(data):
    """The whole WebSocket messages at the start of `data` (the server's:
    unmasked, unfragmented) as [(opcode, payload)], and the bytes after them."""
    found = []
    while len(data) >= 2:
        length, at = data[1] & 0x7F, 2
        if length >= 126:
            at = 4 if length == 126 else 10
            if len(data) < at:
                break
            length = int.from_bytes(data[2:at], "big")
        if len(data) < at + length:
            break
        found.append((data[0] & 0x0F, data[at:at + length]))
        data = data[at + length:]
    return found, data


def test_a_stepped_run_serves_its_ticks_to_the_browser_view():
    """--web on a Lockstep: the page is served, and the stream's states carry
    each step's tick and the pose it was given."""
    import json
    import socket
    import time
    import urllib.request

    with sandbox.Lockstep(args=["--web", "0"]) as run:
        assert run.web_url.startswith("http://127.0.0.1:"), run.web_url
        with urllib.request.urlopen(run.web_url, timeout=30) as page:
            assert page.status == 200 and b"<html" in page.read().lower()
        host, port = run.web_url[len("http://"):].rstrip("/").rsplit(":", 1)
        connection = socket.create_connection((host, int(port)), timeout=30)
        connection.sendall(("GET /stream HTTP/1.1\r\nHost: %s:%s\r\nUpgrade: websocket\r\n"
                            "Connection: Upgrade\r\nSec-WebSocket-Version: 13\r\n"
                            "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n\r\n"
                            % (host, port)).encode())
        data = b""
        while b"\r\n\r\n" not in data:
            data += connection.recv(4096)
        head, data = data.split(b"\r\n\r\n", 1)
        assert head.startswith(b"HTTP/1.1 101"), head
        connection.settimeout(0.02)
        received, given, shown = [], {}, 0
        deadline = time.monotonic() + 60
        while shown < 3 and time.monotonic() < deadline:  # states go out at most 60 a second
            position = (float(len(given)), -100.0, 40.0)
            given[run.step(poses={"ELAHA": (position, (1.0, 0.0, 0.0, 0.0))}).tick] = position
            try:
                data += connection.recv(1 << 20)
            except socket.timeout:
                continue
            found, data = frames(data)
            received += found
            for opcode, payload in found:
                if opcode == 1 and json.loads(payload)["type"] == "state":
                    state = json.loads(payload)
                    assert state["robots"][0]["p"] == pytest.approx(given[state["tick"]],
                                                                    abs=1e-6), state["tick"]
                    shown += 1
        connection.close()
        assert received[0][0] == 1 and json.loads(received[0][1])["type"] == "level"
        assert received[1][0] == 2  # the level's glTF
        assert shown >= 3, "fewer than 3 states in 60 s"

"""MCAP recordings (`--record FILE.mcap`, `sandbox convert`, `--replay FILE.mcap`)
read by Foxglove's own reader (npm @mcap/core with Debian's nodejs,
tests/js/mcap_check.cjs: every CRC, index and the summary checked there), and
compared message by message with the LCM log of the same run, read here from
lcm-logger's format (not the project's reader)."""
import base64
import hashlib
import json
import os
import pathlib
import struct
import subprocess

import numpy as np
import pytest

import sandbox
from test_lockstep import encoded_inputs, write_log

SANDBOX = os.environ.get("SANDBOX", "sandbox")
ROOT = pathlib.Path(__file__).resolve().parents[2]
CHECK = ROOT / "tests/js/mcap_check.cjs"
NODE_PATH = os.environ.get("NODE_PATH", str(ROOT / "build/node/node_modules"))


def lcm_events(path):
    """(channel, utime, data) an event of an LCM log, read from lcm-logger's format."""
    data, at = path.read_bytes(), 0
    while at < len(data):
        sync, _, utime, channel_bytes, data_bytes = struct.unpack_from(">IqqII", data, at)
        assert sync == 0xEDA1DA01
        at += 28
        channel = data[at:at + channel_bytes].decode()
        at += channel_bytes
        yield channel, utime, data[at:at + data_bytes]
        at += data_bytes


def lcm_log(path):
    """(channel, time in ns, SHA-256 of the data) an event of an LCM log."""
    return [[channel, str(utime * 1000), hashlib.sha256(data).hexdigest()]
            for channel, utime, data in lcm_events(path)]


def read_mcap(path):
    assert (pathlib.Path(NODE_PATH) / "@mcap/core").is_dir(), \
        f"the npm readers are not in {NODE_PATH}: run scripts/setup"
    done = subprocess.run(["node", str(CHECK), str(path)], capture_output=True, text=True,
                          env={**os.environ, "NODE_PATH": NODE_PATH})
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def program(*args, check=True):
    return subprocess.run([SANDBOX, *map(str, args)], capture_output=True, text=True, check=check)


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """The sample level replaying 40 poses and bends, recorded as an LCM log and as MCAP."""
    folder = tmp_path_factory.mktemp("mcap")
    write_log(folder / "inputs.lcmlog", encoded_inputs())
    for name in ("run.lcmlog", "run.mcap"):
        program("run", "--replay", folder / "inputs.lcmlog", "--record", folder / name)
    return folder


def test_a_recording_holds_every_input_and_every_message_of_the_lcm_log_with_its_type(runs):
    """The LCM log holds what the run published; MCAP also the inputs it took,
    stamped with their own times."""
    mcap = read_mcap(runs / "run.mcap")
    inputs = lcm_log(runs / "inputs.lcmlog")
    assert sorted(mcap["messages"]) == sorted(lcm_log(runs / "run.lcmlog") + inputs)
    assert [m for m in mcap["messages"] if m[0] in ("ELAHA/POSE", "ELAHA/BONES")] == inputs
    assert len(mcap["messages"]) > 100
    assert mcap["compression"] == ["zstd"]
    lcm_types = {p.stem: p.read_text() for p in (ROOT / "bridge/lcmtypes").glob("*.lcm")}
    for topic, channel in mcap["channels"].items():
        if channel["message_encoding"] == "json":
            continue  # Foxglove's schemas: below
        assert channel["message_encoding"] == "lcm", topic
        assert channel["schema_encoding"] == "lcm", topic
        assert channel["schema_text"] == lcm_types[channel["schema"].removeprefix("sandbox_msgs.")]
    assert mcap["channels"]["ELAHA/STATE"]["schema"] == "sandbox_msgs.robot_state_t"
    assert mcap["channels"]["ELAHA/SCAN_FACE"]["schema"] == "sandbox_msgs.scan_face_t"


def test_compressed_it_is_at_most_seven_tenths_of_the_lcm_log(runs):
    """The same messages (and their Foxglove views): a recording also holds the
    inputs and the scene, written once (the record benchmark measures a whole run)."""
    program("convert", runs / "run.lcmlog", runs / "same.mcap")
    ratio = (runs / "same.mcap").stat().st_size / (runs / "run.lcmlog").stat().st_size
    assert ratio <= 0.7


def test_convert_there_and_back_gives_the_same_bytes_in_either_compression(runs):
    for compression in ("lz4", "none", "zstd"):
        mcap = runs / f"converted-{compression}.mcap"
        program("convert", runs / "run.lcmlog", mcap, "--compression", compression)
        read = read_mcap(mcap)
        assert read["messages"] == lcm_log(runs / "run.lcmlog")
        assert read["compression"] == ["" if compression == "none" else compression]
        program("convert", mcap, runs / "back.lcmlog")
        assert (runs / "back.lcmlog").read_bytes() == (runs / "run.lcmlog").read_bytes()


def test_a_replay_of_mcap_inputs_equals_the_replay_of_the_lcm_log(runs):
    program("convert", runs / "inputs.lcmlog", runs / "inputs.mcap")
    program("run", "--replay", runs / "inputs.mcap", "--record", runs / "from-mcap.lcmlog")
    assert (runs / "from-mcap.lcmlog").read_bytes() == (runs / "run.lcmlog").read_bytes()


def test_a_recording_replays_from_its_own_inputs_to_the_same_outputs(runs):
    """The recorded inputs (POSE, BONES, with their own times) come before their tick's
    STATE: the replay takes them, not the states, and publishes what the run did."""
    replayed = program("run", "--replay", runs / "run.mcap", "--record", runs / "again.lcmlog")
    assert "holds what a run applied" not in replayed.stderr + replayed.stdout
    assert (runs / "again.lcmlog").read_bytes() == (runs / "run.lcmlog").read_bytes()


def test_a_damaged_file_is_refused_naming_it_and_the_offset(runs):
    bytes_ = bytearray((runs / "run.mcap").read_bytes())
    bytes_[200] ^= 0xFF  # inside the first chunk, which starts at byte 32
    bad = runs / "bad.mcap"
    bad.write_bytes(bytes_)
    converted = program("convert", bad, runs / "bad.lcmlog", check=False)
    assert converted.returncode == 1
    assert f"'{bad}' is damaged at byte 32: " in converted.stderr  # zstd's error or the CRC
    replayed = program("run", "--replay", bad, check=False)
    assert f"the log '{bad}' is damaged at byte 32" in replayed.stderr
    truncated = runs / "cut.mcap"
    truncated.write_bytes(bytes_[:5])
    refused = program("run", "--replay", truncated, check=False)
    assert refused.returncode != 0 and str(truncated) in refused.stderr


def test_read_log_reads_a_recording_in_either_format_alike(runs):
    from_log, from_mcap = sandbox.read_log(runs / "run.lcmlog"), sandbox.read_log(runs / "run.mcap")
    assert sorted([*from_log.channels, "ELAHA/BONES", "ELAHA/POSE"]) == sorted(from_mcap.channels)
    state_log, state_mcap = from_log["ELAHA/STATE"], from_mcap["ELAHA/STATE"]
    assert len(state_log) == len(state_mcap) == 40
    assert np.array_equal(state_log.utime, state_mcap.utime)
    assert np.array_equal(state_log.array("position"), state_mcap.array("position"))


def check_transform(tf, state):
    """A foxglove.FrameTransform (JSON, parsed) against the robot_state_t it shows."""
    assert tf["parent_frame_id"] == "world" and tf["child_frame_id"] == "ELAHA"
    assert tf["timestamp"]["sec"] * 10**6 + tf["timestamp"]["nsec"] // 1000 == state.utime
    assert [tf["translation"][a] for a in "xyz"] == list(state.position)
    assert [tf["rotation"][a] for a in "wxyz"] == list(state.orientation)


def check_cloud(cloud, face):
    """A foxglove.PointCloud (JSON, parsed) against the scan_face_t it shows: its occupied
    samples."""
    assert cloud["frame_id"] == "world"
    assert cloud["timestamp"]["sec"] * 10**6 + cloud["timestamp"]["nsec"] // 1000 == face.utime
    assert [cloud["pose"]["position"][a] for a in "xyz"] == list(face.origin)
    fields = {f["name"]: (f["offset"], f["type"]) for f in cloud["fields"]}
    kinds = {2: "i1", 6: "<i4", 7: "<f4"}
    dtype = np.dtype({"names": list(fields), "formats": [kinds[t] for _, t in fields.values()],
                      "offsets": [o for o, _ in fields.values()], "itemsize": cloud["point_stride"]})
    points = np.frombuffer(base64.b64decode(cloud["data"]), dtype=dtype)
    occupied = np.asarray(face.occupancy) == 1  # a point a sample that hit, in order
    assert len(points) == occupied.sum()
    xyz = np.stack([points["x"], points["y"], points["z"]], axis=1)
    assert np.array_equal(xyz, np.asarray(face.xyz, np.float32).reshape(-1, 3)[occupied])
    assert np.array_equal(points["surface"], np.asarray(face.surface)[occupied])
    return len(points)


def test_poses_and_face_scans_are_also_foxglove_frame_transforms_and_point_clouds(runs):
    """Each STATE's pose as the FrameTransform world -> ELAHA, each face scan as a
    PointCloud in world whose points and hit ids are the scan's occupied samples', at the
    same time."""
    mcap = read_mcap(runs / "run.mcap")
    assert mcap["channels"]["ELAHA/STATE/tf"]["schema"] == "foxglove.FrameTransform"
    assert mcap["channels"]["ELAHA/STATE/tf"]["schema_encoding"] == "jsonschema"
    assert mcap["channels"]["ELAHA/SCAN_FACE/points"]["schema"] == "foxglove.PointCloud"
    views = {(topic, time): message for topic, time, _, message in mcap["views"]}
    transforms = clouds = points = 0
    for channel, utime, data in lcm_events(runs / "run.lcmlog"):
        if channel == "ELAHA/STATE":
            check_transform(views[("ELAHA/STATE/tf", str(utime * 1000))], sandbox.decode(data))
            transforms += 1
        elif channel == "ELAHA/SCAN_FACE":
            points += check_cloud(views[("ELAHA/SCAN_FACE/points", str(utime * 1000))],
                                  sandbox.decode(data))
            clouds += 1
    assert transforms == 40 and clouds == 40 and points > 1000

"""Foxglove's views of what no LCM message carries, in an MCAP recording (read
with npm @mcap/core, tests/js/mcap_check.cjs) and from the live server (npm
@foxglove/ws-protocol, tests/js/foxglove_client.cjs), checked against facts
derived here: the bundled URDF arm's link frames against forward kinematics
computed from the URDF's XML, the wall camera's images, calibration and optical
frame against its manifest entry and the documented default field of view, the
level's and the arm's geometry (SceneUpdate) against the glTF's bounds and the
URDF's shapes, and the inputs recorded with the times they were given."""
import math
import pathlib
import xml.etree.ElementTree as ET

import numpy as np
import pytest

import sandbox
from test_foxglove import start_client, wait_for
from test_mcap import ROOT, read_mcap

ARM_LEVEL = ROOT / "examples/robots/arm_cell.toml"
URDF = ROOT / "assets/arm/arm.urdf"
BOX = ROOT / "assets/robots/generated/box.gltf"
STEPS = 24
PERIOD_US = 10_000


def rotation_rpy(r, p, y):
    """URDF's fixed-axis roll, pitch, yaw: Rz(y) Ry(p) Rx(r)."""
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), \
        math.cos(y), math.sin(y)
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return rz @ ry @ rx


def rotation_axis(axis, angle):
    k = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K


def numbers(text, default):
    return [float(v) for v in text.split()] if text else default


def forward_kinematics(values):
    """Each link's 4x4 pose in the root link's frame, the movable joints taking
    `values` in the file's order (URDF: child = parent * origin * motion)."""
    root = ET.parse(URDF).getroot()
    poses = {}
    joints = root.findall("joint")
    children = {j.find("child").get("link") for j in joints}
    for link in root.findall("link"):
        if link.get("name") not in children:
            poses[link.get("name")] = np.eye(4)
    movable = iter(values)
    for joint in joints:  # parents come first in this file
        origin = joint.find("origin")
        X = np.eye(4)
        if origin is not None:
            X[:3, :3] = rotation_rpy(*numbers(origin.get("rpy"), [0, 0, 0]))
            X[:3, 3] = numbers(origin.get("xyz"), [0, 0, 0])
        motion = np.eye(4)
        axis = numbers(joint.find("axis").get("xyz"), [1, 0, 0]) \
            if joint.find("axis") is not None else [1, 0, 0]
        if joint.get("type") in ("revolute", "continuous"):
            motion[:3, :3] = rotation_axis(axis, next(movable))
        elif joint.get("type") == "prismatic":
            motion[:3, 3] = np.asarray(axis) / np.linalg.norm(axis) * next(movable)
        poses[joint.find("child").get("link")] = \
            poses[joint.find("parent").get("link")] @ X @ motion
    return poses


def matrix_of(transform):
    q = transform["rotation"]
    w, x, y, z = q["w"], q["x"], q["y"], q["z"]
    X = np.eye(4)
    X[:3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                 [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                 [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    X[:3, 3] = [transform["translation"][a] for a in "xyz"]
    return X


def utime_of(stamp):
    return stamp["sec"] * 10**6 + stamp["nsec"] // 1000


def joint_values(k):
    """Step k's joints (base_yaw, shoulder, elbow, extend, wrist_roll), within the limits."""
    rng = np.random.default_rng(1000 + k)
    return [rng.uniform(-3, 3), rng.uniform(-1.4, 1.4), rng.uniform(-2, 2),
            rng.uniform(0, 0.15), rng.uniform(-2.9, 2.9)]


BASE_POSE = ((1.0, 0.5, 0.0), (math.cos(0.2), 0.0, 0.0, math.sin(0.2)))


def step(run, k):
    return run.step(poses={"arm": BASE_POSE}, joints={"arm": joint_values(k)},
                    utime=k * PERIOD_US)


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    folder = tmp_path_factory.mktemp("views")
    with sandbox.Lockstep(level=str(ARM_LEVEL),
                          args=["--out", str(folder / "out"), "--record",
                                str(folder / "arm.mcap")]) as run:
        for k in range(STEPS):
            step(run, k)
    return folder, read_mcap(folder / "arm.mcap")


def views_on(mcap, topic):
    return [(int(time), message) for t, time, _, message in mcap["views"] if t == topic]


def check_links(message, k):
    expected = forward_kinematics(joint_values(k))
    by_child = {t["child_frame_id"]: t for t in message["transforms"]}
    assert set(by_child) == {f"arm/{link}" for link in expected}
    for link, X in expected.items():
        transform = by_child[f"arm/{link}"]
        assert transform["parent_frame_id"] == "arm"
        assert np.allclose(matrix_of(transform), X, atol=1e-9), link


def test_link_frames_follow_the_urdfs_forward_kinematics(recording):
    _, mcap = recording
    assert mcap["channels"]["arm/links"]["schema"] == "foxglove.FrameTransforms"
    links = views_on(mcap, "arm/links")
    assert [time for time, _ in links] == [k * PERIOD_US * 1000 for k in range(STEPS)]
    for k, (_, message) in enumerate(links):
        check_links(message, k)
    # The robot's own frame in the world, from its STATE.
    for time, message in views_on(mcap, "arm/STATE/tf"):
        assert message["child_frame_id"] == "arm" and message["parent_frame_id"] == "world"
        assert [message["translation"][a] for a in "xyz"] == list(BASE_POSE[0])


def test_inputs_are_recorded_with_the_times_they_were_given(recording):
    _, mcap = recording
    for channel, schema in (("arm/POSE", "sandbox_msgs.robot_pose_t"),
                            ("arm/JOINTS", "sandbox_msgs.joint_values_t")):
        assert mcap["channels"][channel]["schema"] == schema
        times = [int(time) for topic, time, _ in mcap["messages"] if topic == channel]
        assert times == [k * PERIOD_US * 1000 for k in range(STEPS)]
    # An input's pose is not a second frame for the robot: STATE gives it.
    assert "arm/POSE/tf" not in mcap["channels"]


def jpeg_size(data):
    """(width, height) from a JPEG's start-of-frame marker."""
    at = 2
    while at < len(data):
        marker, length = data[at + 1], int.from_bytes(data[at + 2:at + 4], "big")
        if marker in (0xC0, 0xC1, 0xC2):
            return int.from_bytes(data[at + 7:at + 9], "big"), \
                int.from_bytes(data[at + 5:at + 7], "big")
        at += 2 + length
    raise AssertionError("no start of frame")


def test_camera_frames_come_with_calibration_and_optical_frame(recording):
    import base64
    folder, mcap = recording
    images = views_on(mcap, "camera/wall/image")
    # rate_hz = 10 at 100 Hz steps: ticks 0, 10, 20.
    assert [time for time, _ in images] == [k * PERIOD_US * 1000 for k in (0, 10, 20)]
    written = sorted((folder / "out/wall").glob("wall_*.jpg"))
    assert len(written) == len(images)
    for (time, image), path in zip(images, written):
        data = base64.b64decode(image["data"])
        assert image["format"] == "jpeg" and image["frame_id"] == "camera/wall"
        assert data == path.read_bytes()
        assert jpeg_size(data) == (640, 480)
    f = 240 / math.tan(math.radians(60) / 2)  # the documented default fov_deg = 60
    for time, calibration in views_on(mcap, "camera/wall/calibration"):
        assert calibration["frame_id"] == "camera/wall"
        assert (calibration["width"], calibration["height"]) == (640, 480)
        assert np.allclose(calibration["K"], [f, 0, 319.5, 0, f, 239.5, 0, 0, 1])
        assert np.allclose(calibration["P"], [f, 0, 319.5, 0, 0, f, 239.5, 0, 0, 0, 1, 0])
        assert calibration["distortion_model"] == "plumb_bob" and calibration["D"] == [0] * 5
    # The optical frame (x right, y down, z forward) of the manifest's pose
    # (position [1.8, -1.2, 0.9], rpy_deg [0, 15, 146]: x forward, y left, z up).
    R = rotation_rpy(*np.radians([0, 15, 146]))
    for time, message in views_on(mcap, "camera/wall/tf"):
        (transform,) = message["transforms"]
        assert transform["parent_frame_id"] == "world"
        assert transform["child_frame_id"] == "camera/wall"
        X = matrix_of(transform)
        assert np.allclose(X[:3, 3], [1.8, -1.2, 0.9])
        assert np.allclose(X[:3, 2], R[:, 0], atol=1e-9)   # looks forward
        assert np.allclose(X[:3, 0], -R[:, 1], atol=1e-9)  # right = -left
        assert np.allclose(X[:3, 1], -R[:, 2], atol=1e-9)  # down = -up


def points_of(triangles):
    return np.array([[p[a] for a in "xyz"] for p in triangles["points"]])


def in_frame(triangles):
    """The triangle list's points in its entity's frame (through the primitive's pose)."""
    X = matrix_of({"rotation": triangles["pose"]["orientation"],
                   "translation": triangles["pose"]["position"]})
    points = points_of(triangles)
    return points @ X[:3, :3].T + X[:3, 3]


def check_scene(scene):
    entities = {e["id"]: e for e in scene["entities"]}
    # The floor: box.gltf's bounds scaled by [4, 4, 0.1] at [0, 0, -0.05].
    import json
    accessor = next(a for a in json.loads(BOX.read_text())["accessors"] if "min" in a)
    low = np.array(accessor["min"]) * [4, 4, 0.1] + [0, 0, -0.05]
    high = np.array(accessor["max"]) * [4, 4, 0.1] + [0, 0, -0.05]
    floor = entities["actor/floor/0"]
    assert floor["frame_id"] == "world"
    points = in_frame(floor["triangles"][0])
    assert np.allclose(points.min(axis=0), low, atol=1e-6)
    assert np.allclose(points.max(axis=0), high, atol=1e-6)
    triangles = floor["triangles"][0]
    assert len(triangles["indices"]) == 36 and max(triangles["indices"]) < len(points)
    # The arm: each link's visual in that link's frame (URDF <visual>).
    by_frame = {e["frame_id"]: in_frame(e["triangles"][0]) for e in entities.values()
                if e["id"].startswith("robot/arm/")}
    assert set(by_frame) == {f"arm/{link}" for link in forward_kinematics([0] * 5)}
    wrist = by_frame["arm/wrist"]  # a sphere of radius 0.04 at the link's origin
    assert np.allclose(np.linalg.norm(wrist, axis=1), 0.04, atol=1e-6)
    upper = by_frame["arm/upper_arm"]  # a 0.08 x 0.08 x 0.4 box at z 0.2
    assert np.allclose(upper.min(axis=0), [-0.04, -0.04, 0.0], atol=1e-6)
    assert np.allclose(upper.max(axis=0), [0.04, 0.04, 0.4], atol=1e-6)


def test_the_level_and_the_arm_are_a_scene_update(recording):
    _, mcap = recording
    assert mcap["channels"]["scene"]["schema"] == "foxglove.SceneUpdate"
    (scene,) = views_on(mcap, "scene")
    assert scene[0] == 0  # written once, at the first tick
    check_scene(scene[1])


def test_a_live_client_gets_the_scene_and_link_frames_after_the_run_started():
    seen = []
    with sandbox.Lockstep(level=str(ARM_LEVEL), args=["--foxglove", "0"]) as run:
        for k in range(3):  # before any client: the scene is kept for later ones
            step(run, k)
        client, events = start_client(run.foxglove_url)
        has = lambda topic: lambda s: any(e["event"] == "message" and e["topic"] == topic
                                          for e in s)
        assert wait_for(events, seen, has("scene")), [e.get("topic") for e in seen]
        k = 3
        while not has("arm/links")(seen) and k < 40:
            step(run, k)
            k += 1
            wait_for(events, seen, has("arm/links"), seconds=5.0)
        assert has("arm/links")(seen)
    client.terminate()
    client.wait(timeout=30)
    scene = next(e for e in seen if e["event"] == "message" and e["topic"] == "scene")
    assert scene["schemaName"] == "foxglove.SceneUpdate"
    check_scene(scene["message"])
    for event in seen:
        if event["event"] == "message" and event["topic"] == "arm/links":
            check_links(event["message"], utime_of(event["message"]["transforms"][0]["timestamp"])
                        // PERIOD_US)

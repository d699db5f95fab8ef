"""The Python module against the command line and against facts.

Each scan from Python is compared with `sandbox scan`'s CSV of the same scan
(the same level, pose and settings through the program), sample by sample;
the sample terrain's heights under vertical rays with its analytic formula
(assets/generators/sample_terrain.h, restated here); the arrays are views of
the scan's own buffers (read-only, alive as long as the arrays are).
Run by ctest with PYTHONPATH=build/python and SANDBOX=build/sandbox.
"""
import csv
import math
import os
import subprocess
import threading

import numpy as np
import pytest

import sandbox
from sample_terrain import terrain_height

SANDBOX = os.environ.get("SANDBOX", "sandbox")


@pytest.fixture(scope="module")
def world():
    return sandbox.World()


def yaw(degrees):
    """The quaternion (w, x, y, z) of a turn about the world's z axis."""
    half = math.radians(degrees) / 2
    return (math.cos(half), 0.0, 0.0, math.sin(half))


def scan_csv(tmp_path, *args):
    """`sandbox scan` into a CSV: its rows as dicts of floats."""
    out = tmp_path / "scan.csv"
    subprocess.run([SANDBOX, "scan", *args, "--out", str(out)], check=True,
                   stdout=subprocess.DEVNULL)
    with open(out) as f:
        return [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]


def test_face_scan_equals_the_command_lines(world, tmp_path):
    rows = scan_csv(tmp_path, "--at", "10,20,15,0,0,30", "--resolution", "2",
                    "--half-extent", "20")
    scan = world.face_scan((10, 20, 15), yaw(30), resolution=2, half_extent=20)
    n = scan.n
    assert n == 21 and len(rows) == 6 * n * n
    points = scan.points()
    hits = 0
    for row in rows:
        f, r, c = int(row["face"]), int(row["row"]), int(row["col"])
        assert scan.occupancy[f][r, c] == row["occupancy"], (f, r, c)
        assert scan.surface[f][r, c] == row["surface"], (f, r, c)
        assert np.allclose(points[f, r, c], (row["x"], row["y"], row["z"]), atol=1e-5), (f, r, c)
        assert np.allclose(scan.normal[f][r, c], (row["nx"], row["ny"], row["nz"]), atol=1e-5)
        hits += row["occupancy"] == 1
    assert hits > 100  # the scan sees the ground below


def test_lidar_and_ground_and_ray_equal_the_command_lines(world, tmp_path):
    rows = scan_csv(tmp_path, "--at", "-30,5,25,0,0,-60", "--sensor", "lidar", "--lidar",
                    "channels = 8, azimuth_steps = 256, intensity = true")
    scan = world.lidar_scan((-30, 5, 25), yaw(-60),
                            settings="channels = 8, azimuth_steps = 256, intensity = true")
    assert (scan.channels, scan.steps) == (8, 256) and len(rows) == 8 * 256
    for row in rows:
        c, k = int(row["channel"]), int(row["step"])
        assert scan.hit[c, k] == row["hit"]
        assert scan.range[c, k] == pytest.approx(row["range"], abs=1e-4)
        assert scan.intensity[c, k] == pytest.approx(row["intensity"], abs=1e-6)
        assert np.allclose(scan.points[c, k], (row["x"], row["y"], row["z"]), atol=1e-5)
        assert scan.surface[c, k] == row["surface"]
    assert scan.hit.sum() > 500

    rows = scan_csv(tmp_path, "--at", "40,-20,50", "--sensor", "ground", "--resolution", "3",
                    "--half-extent", "30")
    ground = world.ground_scan((40, -20, 50), resolution=3, half_extent=30)
    assert len(rows) == ground.n ** 2
    for row in rows:
        r, c = int(row["row"]), int(row["col"])
        if row["valid"]:
            assert ground.height[r, c] == pytest.approx(row["z"], abs=1e-5)
        else:
            assert math.isnan(ground.height[r, c])
        assert ground.surface[r, c] == row["surface"]

    row, = scan_csv(tmp_path, "--at", "3,4,70", "--sensor", "ray")
    ray = world.ray((3, 4, 70))
    assert ray["hit"] == bool(row["hit"])
    assert ray["range"] == pytest.approx(row["range"], abs=1e-5)
    assert ray["surface"] == row["surface"]


def test_vertical_rays_meet_the_analytic_terrain(world):
    terrain = {s["id"] for s in world.surfaces() if s["name"] == "terrain"}
    assert terrain, world.surfaces()
    checked = 0
    for col in range(20, 190, 17):
        for row in range(20, 190, 23):
            x, y = -200.0 + 2 * col, 200.0 - 2 * row  # grid vertices: the mesh's own heights
            ray = world.ray((x, y, 90))
            if ray["surface"] not in terrain:
                continue  # something stands there
            assert ray["point"][2] == pytest.approx(terrain_height(x, y), abs=1e-4), (x, y)
            checked += 1
    assert checked >= 40


def test_arrays_view_the_scan_and_keep_it_alive(world):
    scan = world.lidar_scan((0, 0, 30))
    ranges, points = scan.range, scan.points
    assert ranges.__array_interface__["data"][0] == scan._addresses()["range"]
    assert points.__array_interface__["data"][0] == scan._addresses()["points"]
    assert not ranges.flags.writeable and not ranges.flags.owndata
    with pytest.raises(ValueError):
        ranges[0, 0] = 1.0
    expected = ranges.copy()
    del scan  # the arrays keep it
    other = world.lidar_scan((50, 50, 30))  # a new scan, maybe where a freed one was
    assert not np.array_equal(other.range, expected)
    assert np.array_equal(ranges, expected) and points.shape == (16, 1024, 3)


def test_a_posed_robot_is_seen_where_it_was_put(world):
    # Straight above a robot at 40 m, a ray down that sees robots meets it.
    world.set_pose("ELAHA", (0, -100, 40), yaw(90))
    position, orientation = world.pose("ELAHA")
    assert position == pytest.approx((0, -100, 40))
    assert orientation == pytest.approx(yaw(90))
    seen = world.ray((0, -100, 60), see_robots=True)
    robot = {s["id"] for s in world.surfaces() if s["robot"] == "ELAHA"}
    assert seen["surface"] in robot and 15 < seen["range"] < 21, seen
    assert world.ray((0, -100, 60))["surface"] not in robot
    world.set_pose("ELAHA", (0, -300, 40))
    assert world.ray((0, -100, 60), see_robots=True)["surface"] not in robot


def test_scans_from_threads_agree(world):
    first = world.face_scan((5, 5, 20), resolution=1).points()
    results = [None] * 4

    def scan(i):
        results[i] = world.face_scan((5, 5, 20), resolution=1).points()

    threads = [threading.Thread(target=scan, args=(i,)) for i in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for points in results:
        assert np.array_equal(points, first, equal_nan=True)


def test_bad_arguments_are_python_errors_naming_them(world):
    with pytest.raises(ValueError, match="position must be 3 numbers"):
        world.face_scan((1, 2))
    with pytest.raises(ValueError, match="position must be finite"):
        world.ray((0, float("nan"), 3))
    with pytest.raises(ValueError, match="unit quaternion"):
        world.ray((0, 0, 3), (2, 0, 0, 0))
    with pytest.raises(ValueError, match="resolution must be a positive number"):
        world.face_scan((0, 0, 3), resolution=-1)
    with pytest.raises(ValueError, match="aligned must be"):
        world.face_scan((0, 0, 3), aligned="sideways")
    with pytest.raises(KeyError, match="no robot 'NOPE'; the level has: ELAHA"):
        world.set_pose("NOPE", (0, 0, 0))
    with pytest.raises(ValueError, match="values must be 45 numbers"):
        world.set_bones("ELAHA", [0.0] * 44)
    with pytest.raises(ValueError, match="settings"):
        world.lidar_scan((0, 0, 3), settings="channels = -2")
    with pytest.raises(sandbox.LevelError, match="/nonexistent/level.toml"):
        sandbox.World("/nonexistent/level.toml")


def read_png(path):
    from PIL import Image
    return np.array(Image.open(path))


def test_render_equals_the_command_lines(world, tmp_path):
    out = tmp_path / "look.png"
    subprocess.run([SANDBOX, "render", "--camera", "fixed", "--at", "-15,-45,32,0,0,45",
                    "--robot-at", "0,-30,30", "--width", "160", "--height", "120",
                    "--kind", "color,depth,segmentation", "--out", str(out)],
                   check=True, stdout=subprocess.DEVNULL)
    world.set_pose("ELAHA", (0, -30, 30))
    frame = world.render("fixed", (-15, -45, 32), yaw(45), width=160, height=120,
                         kinds="color,depth,segmentation")
    assert (frame.width, frame.height) == (160, 120) and frame.normals is None
    assert np.array_equal(frame.color, read_png(out)[:, :, :3])
    millimetres = read_png(tmp_path / "look_depth.png").astype(np.int64)
    depth = frame.depth
    near = np.isfinite(depth) & (depth < 60)
    assert near.sum() > 1000
    assert np.abs(np.round(depth[near] * 1000) - millimetres[near]).max() <= 1
    assert np.array_equal(frame.segmentation, read_png(tmp_path / "look_seg.png"))
    robot = {s["id"] for s in world.surfaces() if s["robot"] == "ELAHA"}
    assert np.isin(frame.segmentation, list(robot)).sum() > 50  # the wing is in the picture


ARM = os.path.join(os.path.dirname(__file__), "..", "..", "assets", "arm", "arm.urdf")


def test_joints_by_name_are_drawn_as_sandbox_render_draws_them(tmp_path):
    arm = sandbox.World(ARM)  # a URDF alone: loaded apart first, by the sandbox program
    assert arm.robots == ["arm"]
    assert list(arm.joints("arm")) == ["base_yaw", "shoulder", "elbow", "extend", "wrist_roll"]
    arm.set_joints("arm", {"shoulder": math.radians(30), "elbow": math.radians(-45)})
    assert arm.joints("arm")["shoulder"] == math.radians(30)
    out = tmp_path / "arm.png"
    subprocess.run([SANDBOX, "render", ARM, "--camera", "fixed", "--at", "1.4,0.3,0.5,0,0,190",
                    "--bones", "shoulder 30; elbow -45", "--width", "160", "--height", "120",
                    "--kind", "color,segmentation", "--out", str(out)],
                   check=True, stdout=subprocess.DEVNULL)
    frame = arm.render("fixed", (1.4, 0.3, 0.5), yaw(190), width=160, height=120,
                       kinds="color,segmentation")
    assert np.array_equal(frame.color, read_png(out)[:, :, :3])
    assert np.array_equal(frame.segmentation, read_png(tmp_path / "arm_seg.png"))
    assert (frame.segmentation > 0).sum() > 500  # the arm is in the picture
    rest = sandbox.World(ARM).render("fixed", (1.4, 0.3, 0.5), yaw(190), width=160, height=120,
                                     kinds="segmentation")
    assert (rest.segmentation != frame.segmentation).sum() > 100  # and the joints moved it
    with pytest.raises(KeyError, match="base_yaw, shoulder"):
        arm.set_joints("arm", {"knee": 0.1})
    with pytest.raises(ValueError, match="limits"):
        arm.set_joints("arm", {"shoulder": 0.2, "extend": 1.0})
    assert arm.joints("arm")["shoulder"] == math.radians(30)  # all or none


def test_declared_sensors_run_as_the_loop_runs_them(world):
    """The altimeter equals a ray from its mount; the scanner's scan equals an ad-hoc face
    scan of its settings at the robot's pose, without its own robot."""
    assert world.sensors == [("ELAHA", "scanner", "face"), ("ELAHA", "altimeter", "ray")]
    world.set_pose("ELAHA", (10, 20, 40), yaw(30))
    altimeter = world.scan("altimeter")
    assert altimeter == world.ray((10, 20, 40), yaw(30), range=200)
    assert abs(altimeter["point"][2] - terrain_height(10, 20)) < 0.05
    scan = world.scan("scanner")
    alone = world.face_scan((10, 20, 40), yaw(30), resolution=1, half_extent=25)
    for face in range(6):
        assert np.array_equal(scan.distance[face], alone.distance[face])
    with pytest.raises(KeyError, match="scanner, altimeter"):
        world.scan("camera")
    with pytest.raises(KeyError, match="ELAHA"):
        world.scan("scanner", robot="NOBODY")


def test_movable_actors_are_placed(world):
    assert world.actors == ["gate"]
    before = world.ray((0, 0, 150), range=200)
    world.set_actor("gate", (0, 0, 100))
    hit = world.ray((0, 0, 150), range=200)
    assert hit["hit"] and hit["point"][2] > 100 > before["point"][2]
    gate = [s["id"] for s in world.surfaces() if s["name"] == "gate"]
    assert hit["surface"] in gate
    assert world.actor_pose("gate") == ((0.0, 0.0, 100.0), (1.0, 0.0, 0.0, 0.0))
    with pytest.raises(KeyError, match="gate"):
        world.set_actor("terrain", (0, 0, 0))


def test_declared_cameras_equal_the_loops_frames(tmp_path):
    """The loop's own first frames (Lockstep --out) and render_camera at that pose."""
    world = sandbox.World()
    assert [c[1] for c in world.cameras] == ["chase", "trailing", "belly"]
    with sandbox.Lockstep(args=["--out", str(tmp_path), "--frames", "png"]) as run:
        run.step(poses={"ELAHA": ((10, -40, 45), yaw(20))})
    world.set_pose("ELAHA", (10, -40, 45), yaw(20))
    chase = world.render_camera("chase")
    assert np.array_equal(chase.color, read_png(tmp_path / "chase/chase_000000.png")[:, :, :3])
    belly = world.render_camera("belly")
    assert (belly.width, belly.height) == (320, 240)
    assert np.array_equal(belly.color, read_png(tmp_path / "belly/belly_000000.png")[:, :, :3])
    millimetres = read_png(tmp_path / "belly/belly_000000_depth.png").astype(np.int64)
    near = np.isfinite(belly.depth) & (belly.depth < 60)
    assert near.sum() > 1000
    assert np.abs(np.round(belly.depth[near] * 1000) - millimetres[near]).max() <= 1
    with pytest.raises(KeyError, match="chase, trailing, belly"):
        world.render_camera("nose")

"""examples/python/ on a small case: the dataset writer's files are what its
index says, its images those `sandbox render` draws at the pose the index
gives, its scans around that pose; the wing's loop as its formula says.
controller_bench.py runs in test_client.py."""
import csv
import os
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
EXAMPLES = os.path.join(HERE, "..", "..", "examples", "python")


def test_the_dataset_writer(tmp_path):
    out = tmp_path / "dataset"
    subprocess.run([sys.executable, os.path.join(EXAMPLES, "dataset.py"), str(out), "3",
                    "--size", "96x72", "--seed", "5"], check=True, stdout=subprocess.DEVNULL)
    with open(out / "index.csv") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 3
    with open(out / "surfaces.csv") as f:
        robot = {int(r["id"]) for r in csv.DictReader(f) if r["robot"] == "ELAHA"}
    for row in rows:
        images = np.load(out / row["images"])
        assert images["color"].shape == (72, 96, 3)
        look = tmp_path / ("look%s.png" % row["sample"])
        subprocess.run([os.environ.get("SANDBOX", "sandbox"), "render", "--camera", "chase",
                        "--at", "%s,%s,%s,0,0,%s" % (row["x"], row["y"], row["z"], row["heading_deg"]),
                        "--width", "96", "--height", "72", "--kind", "color,segmentation",
                        "--out", str(look)], check=True, stdout=subprocess.DEVNULL)
        from PIL import Image
        drawn = np.array(Image.open(look))[:, :, :3]
        assert (images["color"] == drawn).all(axis=2).mean() > 0.999, row
        segments = np.array(Image.open(tmp_path / ("look%s_seg.png" % row["sample"])))
        assert (images["segmentation"] == segments).mean() > 0.999, row
        assert np.isin(images["segmentation"], list(robot)).any(), row  # the wing is in it
        points = np.load(out / row["scan"])
        assert points.shape == (6, 51, 51, 3)
        # The scan is centred on the pose: its box's faces are 25 m either side of it.
        centre = np.array([float(row["x"]), float(row["y"]), float(row["z"])])
        assert np.nanmax(np.abs(points - centre)) <= 25 * 3 ** 0.5 + 1e-6
        assert int(row["hits"]) > 100  # the ground is within 20 m below


def test_fly_wing(tmp_path):
    """The loop flown as its formula says (restated), the chase frames at the camera's
    30 Hz of 100 Hz ticks, the plot written, no input refused."""
    import json
    import math
    ticks = 60
    subprocess.run([sys.executable, os.path.join(EXAMPLES, "fly_wing.py"), str(tmp_path),
                    "--ticks", str(ticks)], check=True, stdout=subprocess.DEVNULL)
    flight = json.loads((tmp_path / "flight.json").read_text())
    assert flight["refused"] == "" and flight["frames"] == ticks * 30 // 100
    for k, position in enumerate(flight["positions"]):
        angle = 2 * math.pi * k / ticks
        assert np.allclose(position, (40 * math.sin(angle), -60, 70 - 40 * math.cos(angle)),
                           atol=1e-9)
    assert flight["occupied"] > 0
    assert (tmp_path / "face_down.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_autopilot_view(tmp_path):
    """The instruments of a banked, climbing turn as the turn's own physics says:
    load factor 1 / cos(bank), turn rate v / r, groundspeed v, climbing 2 m/s;
    the wing tip's IMU feels the bending the body's does not."""
    out = tmp_path / "instruments.json"
    printed = subprocess.run([sys.executable, os.path.join(EXAMPLES, "autopilot_view.py"),
                              "--seconds", "3", "--json", str(out)], check=True,
                             capture_output=True, text=True).stdout
    assert len(printed.splitlines()) == 1 + 6  # the header, a line every half second
    import json
    import math
    data = json.loads(out.read_text())
    speed, radius, g0 = 30.0, 300.0, 9.80665
    bank = math.atan(speed * speed / radius / g0)
    force = np.array(data["specific_force"]).reshape(-1, 3)[10:]
    rate = np.array(data["angular_rate"]).reshape(-1, 3)[10:]
    assert len(force) > 1000  # 400 Hz for 3 s
    assert abs(np.linalg.norm(force, axis=1).mean() / g0 - 1 / math.cos(bank)) < 0.005
    assert abs(np.linalg.norm(rate.mean(axis=0)) - speed / radius) < 0.002
    ned = np.array(data["gps_velocity_ned"]).reshape(-1, 3)
    assert np.all(np.abs(np.hypot(ned[:, 0], ned[:, 1]) - speed) < 0.3)
    altitude = np.array(data["pressure_altitude"])
    climb = np.polyfit(np.arange(len(altitude)) / 50.0, altitude, 1)[0]
    assert abs(climb - 2.0) < 0.5
    tip = np.array(data["tip_specific_force"]).reshape(-1, 3)[10:]
    assert tip[:, 2].std() > 3 * force[:, 2].std()

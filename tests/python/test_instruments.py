"""The IMU through the whole program (Lockstep: `sandbox run --lockstep`): the
flying wing on a level circle, its IMU's messages against the circle's own
kinematics, and two runs with one seed giving the same bytes."""
import math
import pathlib

import numpy as np

import sandbox

ASSETS = pathlib.Path(__file__).resolve().parents[2] / "assets"
G0 = 9.80665
V, R = 50.0, 500.0  # m/s, m
OMEGA = V / R


def level(tmp_path):
    wing = ASSETS / "robots/generated/flying_wing.gltf"
    path = tmp_path / "imu.toml"
    path.write_text(f"""
[[robot]]
name = "W"
file = "{wing}"
bones = ["root"]

[[robot.sensor]]
name = "clean"
type = "imu"
rate_hz = 4000

[[robot.sensor]]
name = "noisy"
type = "imu"
rate_hz = 1000
accel_noise_density = 0.002
gyro_noise_density = 0.0003
gyro_bias_random_walk = 0.0001
seed = 5
""")
    return path


def circle(k):
    """The k-th pose at 1 kHz: counter-clockwise, x along the velocity."""
    t = k * 1e-3
    position = (R * math.sin(OMEGA * t), R - R * math.cos(OMEGA * t), 1000.0)
    q = (math.cos(OMEGA * t / 2), 0.0, 0.0, math.sin(OMEGA * t / 2))
    return 1_000_000 + 1000 * k, position, q


def fly(path, ticks=200):
    """Each tick's raw IMU messages and decoded ones."""
    raw, decoded = [], []
    with sandbox.Lockstep(path) as run:
        for k in range(ticks):
            utime, position, q = circle(k)
            outputs = run.step(poses={"W": (position, q)}, utime=utime)
            raw.append([bytes(data) for data in outputs.raw("W/IMU")] if "W/IMU" in outputs
                       else [])
            decoded.append(list(outputs.get("W/IMU", [])))
    return raw, decoded


def test_a_level_circle_gives_v2_over_r_inwards_and_one_g_up(tmp_path):
    _, decoded = fly(level(tmp_path))
    assert decoded[0] == []  # the first pose: nothing before it
    clean = [m for tick in decoded for m in tick if m.sensor == "clean"]
    noisy = [m for tick in decoded for m in tick if m.sensor == "noisy"]
    assert len(clean) == len(noisy) == 199
    times = np.concatenate([m.sample_utime for m in clean])
    assert np.array_equal(np.diff(times), np.full(len(times) - 1, 250))
    assert times[0] == 1_000_250
    force = np.concatenate([m.specific_force.reshape(-1, 3) for m in clean[3:]])
    rate = np.concatenate([m.angular_rate.reshape(-1, 3) for m in clean[3:]])
    assert np.abs(force - [0.0, V * V / R, G0]).max() < 1e-6
    assert np.abs(rate - [0.0, 0.0, OMEGA]).max() < 1e-9
    assert all(m.num_samples == 1 for m in noisy)
    noise = np.concatenate([m.specific_force.reshape(-1, 3) for m in noisy[3:]]) - [0, V * V / R, G0]
    assert 0.02 < noise.std() < 0.2  # 0.002 sqrt(1000) = 0.063


def test_one_seed_gives_the_same_bytes(tmp_path):
    path = level(tmp_path)
    first, _ = fly(path, 60)
    second, _ = fly(path, 60)
    assert sum(len(tick) for tick in first) == 2 * 59
    assert first == second

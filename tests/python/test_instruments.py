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


def wing_level(tmp_path, name, tables):
    """The flying wing with these tables after its [[robot]] table."""
    wing = ASSETS / "robots/generated/flying_wing.gltf"
    path = tmp_path / f"{name}.toml"
    path.write_text(f'[[robot]]\nname = "W"\nfile = "{wing}"\nbones = ["root"]\n' + tables)
    return path


def level(tmp_path):
    return wing_level(tmp_path, "imu", """
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


def anchored_level(tmp_path):
    """The wing with air data and a GNSS receiver, the world anchored at 47 N
    8 E 500 m, a 5 m/s wind towards the east."""
    return wing_level(tmp_path, "anchored", """
[[robot.sensor]]
name = "adc"
type = "air_data"
rate_hz = 1000

[[robot.sensor]]
name = "gps"
type = "gnss"
rate_hz = 10
latency_s = 0.02

[robot.bridge]
geodetic_origin = [47.0, 8.0, 500.0]

[wind]
velocity = [5.0, 0.0, 0.0]
""")


def test_air_data_and_gnss_see_the_circle_through_the_wind(tmp_path):
    with sandbox.Lockstep(anchored_level(tmp_path)) as run:
        air, fixes = [], []
        for k in range(300):
            utime, position, q = circle(k)
            outputs = run.step(poses={"W": (position, q)}, utime=utime)
            air += outputs.get("W/AIR_DATA", [])
            fixes += outputs.get("W/GNSS", [])
    times = np.concatenate([m.sample_utime for m in air[3:]])
    tas = np.concatenate([m.true_airspeed_m_s for m in air[3:]])
    t = (times - 1_000_000) * 1e-6
    # Velocity (V cos wt, V sin wt, 0) less the wind (5, 0, 0).
    expected = np.hypot(V * np.cos(OMEGA * t) - 5.0, V * np.sin(OMEGA * t))
    assert np.abs(tas - expected).max() < 1e-6
    altitude = np.concatenate([m.pressure_altitude_m for m in air])
    assert np.all(np.abs(altitude - 1500.0) < 2.0)  # 1,500 m above the ellipsoid, geopotential
    # Fixes at 10 Hz, each 20 ms after it was taken; 50 m/s horizontal, level.
    fix_times = np.concatenate([m.fix_utime for m in fixes])
    assert np.array_equal(fix_times, 1_000_000 + 100_000 * np.arange(1, 3))
    assert all(m.input_utime - m.fix_utime[0] == 20_000 for m in fixes)
    ned = np.concatenate([m.velocity_ned.reshape(-1, 3) for m in fixes])
    assert np.allclose(np.hypot(ned[:, 0], ned[:, 1]), V, atol=1e-3)
    assert np.allclose(ned[:, 2], 0.0, atol=1e-2)
    heights = np.concatenate([m.height_m for m in fixes])
    assert np.all(np.abs(heights - 1500.0) < 1.0)

#!/usr/bin/python3
"""What a simple autopilot would see of the flying wing: its IMU, air data and
GNSS receiver (examples/instruments/level.toml), not its true pose.

The wing flies a climbing left turn through the level's sheared, gusty wind,
its wings flexing, one tick a step at 100 Hz in the program's own loop
(sandbox.Lockstep); every half second this prints what the instruments say:
load factor and turn rate from the IMU, the tip IMU's extra vertical
acceleration (the wing bending), indicated airspeed, pressure altitude, angle
of attack and sideslip from the air data computer, and groundspeed, track and
height from the GNSS receiver. --json FILE writes every sample it read.

usage: PYTHONPATH=build/python examples/python/autopilot_view.py [--seconds S] [--json FILE]
"""
import argparse
import json
import math
import pathlib

import numpy as np

import sandbox

LEVEL = pathlib.Path(__file__).resolve().parents[1] / "instruments" / "level.toml"
G0 = 9.80665
SPEED, RADIUS, CLIMB = 30.0, 300.0, 2.0  # m/s over the ground, m, m/s
RATE_HZ = 100.0


def pose(t):
    """A climbing left turn, banked for it: position and (w, x, y, z)."""
    omega = SPEED / RADIUS
    heading = omega * t  # from +x, counter-clockwise
    position = (RADIUS * math.sin(heading), RADIUS * (1 - math.cos(heading)), 120.0 + CLIMB * t)
    bank = -math.atan(SPEED * omega / G0)  # left wing down (x forward, y left, z up)
    pitch = -math.atan(CLIMB / SPEED)  # nose up
    # R = Rz(heading) Ry(pitch) Rx(bank), as a quaternion.
    cz, sz = math.cos(heading / 2), math.sin(heading / 2)
    cy, sy = math.cos(pitch / 2), math.sin(pitch / 2)
    cx, sx = math.cos(bank / 2), math.sin(bank / 2)
    q = (cz * cy * cx + sz * sy * sx, cz * cy * sx - sz * sy * cx,
         cz * sy * cx + sz * cy * sx, sz * cy * cx - cz * sy * sx)
    return position, q


def wing_flex(t):
    """Both wings bending up and down together at 1.5 Hz, the tips the most."""
    values = [0.0, 0.0]  # root
    for _side in range(2):
        for k in range(10):
            values += [0.001 * (k + 1) * math.sin(2 * math.pi * 1.5 * t), 0.0]
    return values + [0.0, 0.0, 0.0]  # elevators


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--json", help="write every sample read here")
    args = parser.parse_args()
    read = {"imu": [], "tip_imu": [], "adc": [], "gps": []}
    print(f"{'t s':>5} {'n g':>6} {'turn d/s':>8} {'tip dz':>7} {'IAS m/s':>8} {'alt m':>7} "
          f"{'AoA d':>6} {'beta d':>6} {'GS m/s':>7} {'track d':>7} {'h m':>7}")
    with sandbox.Lockstep(LEVEL, rate_hz=RATE_HZ) as run:
        for k in range(int(args.seconds * RATE_HZ) + 1):
            t = k / RATE_HZ
            position, q = pose(t)
            outputs = run.step(poses={"ELAHA": (position, q)}, bones={"ELAHA": wing_flex(t)})
            for channel in ("ELAHA/IMU", "ELAHA/AIR_DATA", "ELAHA/GNSS"):
                for message in outputs.get(channel, []):
                    read[message.sensor].append(message)
            if k % 50 == 0 and k > 0:
                print(line(t, read))
    if args.json:
        pathlib.Path(args.json).write_text(json.dumps(as_table(read)))


def line(t, read):
    """The last half second's instruments, as an autopilot would average them."""
    imu, tip, adc, gps = (read[name][-20:] for name in ("imu", "tip_imu", "adc", "gps"))
    force = np.concatenate([m.specific_force.reshape(-1, 3) for m in imu])
    rate = np.concatenate([m.angular_rate.reshape(-1, 3) for m in imu])
    tip_force = np.concatenate([m.specific_force.reshape(-1, 3) for m in tip])
    load = np.linalg.norm(force, axis=1).mean() / G0
    turn = math.degrees(np.linalg.norm(rate.mean(axis=0)))
    bending = tip_force[:, 2].std()  # the tip's vertical acceleration the body does not feel
    ias = np.concatenate([m.indicated_airspeed_m_s for m in adc]).mean()
    altitude = np.concatenate([m.pressure_altitude_m for m in adc]).mean()
    aoa = math.degrees(np.concatenate([m.angle_of_attack_rad for m in adc]).mean())
    beta = math.degrees(np.concatenate([m.sideslip_rad for m in adc]).mean())
    fix = gps[-1]
    north, east, _ = fix.velocity_ned[-3:]
    track = math.degrees(math.atan2(east, north)) % 360
    return (f"{t:5.1f} {load:6.3f} {turn:8.2f} {bending:7.2f} {ias:8.2f} {altitude:7.1f} "
            f"{aoa:6.2f} {beta:6.2f} {math.hypot(north, east):7.2f} {track:7.1f} "
            f"{fix.height_m[-1]:7.1f}")


def as_table(read):
    imu = read["imu"]
    adc = read["adc"]
    gps = read["gps"]
    return {
        "imu_utime": np.concatenate([m.sample_utime for m in imu]).tolist(),
        "specific_force": np.concatenate([m.specific_force for m in imu]).tolist(),
        "angular_rate": np.concatenate([m.angular_rate for m in imu]).tolist(),
        "tip_specific_force": np.concatenate([m.specific_force for m in read["tip_imu"]]).tolist(),
        "ias": np.concatenate([m.indicated_airspeed_m_s for m in adc]).tolist(),
        "tas": np.concatenate([m.true_airspeed_m_s for m in adc]).tolist(),
        "pressure_altitude": np.concatenate([m.pressure_altitude_m for m in adc]).tolist(),
        "gps_height": np.concatenate([m.height_m for m in gps]).tolist(),
        "gps_velocity_ned": np.concatenate([m.velocity_ned for m in gps]).tolist(),
    }


if __name__ == "__main__":
    main()

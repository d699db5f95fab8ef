#!/usr/bin/python3
"""A controller test bench driving a running sandbox over LCM.

The controller sees only an instrument, the sandbox's altimeter (<ROBOT>/RANGE):
it flies the wing east at constant speed and holds a height above ground by
commanding its climb rate. Each step publishes the wing's next pose, waits for
the sandbox's STATE of that pose (run the sandbox with --lockstep: one tick a
pose; a pose the sandbox missed while loading is sent again) and reads the
newest altimeter sample. Prints one JSON line: steps, the
height error over the last half of the flight, and the readings.

usage (inside scripts/netns-run, or on your own LCM network):
  sandbox run --lockstep --lcm-url URL &
  PYTHONPATH=build/python examples/python/controller_bench.py --url URL [--steps N]
"""
import argparse
import json
import math

import sandbox


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--url", default="", help="LCM URL (default: LCM's own)")
    parser.add_argument("--robot", default="ELAHA", help="the robot's channel prefix")
    parser.add_argument("--steps", type=int, default=400)
    parser.add_argument("--height", type=float, default=30.0, help="height to hold, m")
    parser.add_argument("--speed", type=float, default=25.0, help="m/s east")
    parser.add_argument("--rate", type=float, default=100.0, help="steps a second")
    parser.add_argument("--out", help="also write every step as CSV here")
    args = parser.parse_args()
    if args.steps < 1 or args.rate <= 0:
        parser.error("--steps must be at least 1 and --rate positive")

    client = sandbox.Client(args.url)
    dt = 1.0 / args.rate
    position = [-150.0, 100.0, 45.0]
    climb, measured, rows = 0.0, None, []
    for step in range(args.steps):
        utime = 1_000_000 + round(step * dt * 1e6)
        state, quiet = None, 0
        client.publish_pose(args.robot, position, (1.0, 0.0, 0.0, 0.0), utime=utime)
        while state is None:  # the tick of this pose: the STATE computed from it
            received = client.receive(timeout=0.1)
            quiet = 0 if received else quiet + 1
            if quiet == 100:
                raise SystemExit(f"no STATE from the sandbox within 10 s ({client.url})")
            if quiet % 10 == 9:  # again after a quiet second: a sandbox still loading missed it
                client.publish_pose(args.robot, position, (1.0, 0.0, 0.0, 0.0), utime=utime)
            for channel, message in received:
                if channel == f"{args.robot}/RANGE" and message.hit:
                    measured = message
                elif channel == f"{args.robot}/STATE" and message.input_utime == utime:
                    state = message
        if measured is not None:  # a proportional climb command on the altimeter's error
            error = args.height - measured.range_m
            climb = max(-10.0, min(10.0, 1.5 * error))
        rows.append({"step": step, "x": state.position[0], "z": state.position[2],
                     "range": None if measured is None else measured.range_m,
                     "ground": None if measured is None else list(measured.point),
                     "range_utime": None if measured is None else measured.input_utime})
        position = [position[0] + args.speed * dt, position[1], position[2] + climb * dt]

    late = [abs(args.height - row["range"]) for row in rows[len(rows) // 2:] if row["range"]]
    summary = {"steps": len(rows), "mean_error_m": sum(late) / len(late),
               "max_error_m": max(late), "dropped": client.dropped, "rows": rows}
    if args.out:
        with open(args.out, "w") as f:
            f.write("step,x,z,range\n")
            for row in rows:
                f.write(f"{row['step']},{row['x']},{row['z']},{row['range']}\n")
    print(json.dumps(summary))
    return 0 if math.isfinite(summary["mean_error_m"]) else 1


if __name__ == "__main__":
    raise SystemExit(main())

#!/usr/bin/python3
"""A face scan and a render through Python against the same from C++ in one
process (target: at most 1.05x each), the arrays' data pointers against
the scan's own buffers (zero copies), and Lockstep.step()'s tick rate against
`sandbox run --replay` of the same inputs (target: at least 0.9x).

usage: PYTHONPATH=build/python bench/python_scan.py [ROUNDS]   (default 7)
"""
import math
import os
import pathlib
import re
import struct
import subprocess
import sys
import tempfile
import time

import sandbox
from sandbox import sandbox_msgs

SANDBOX = os.environ.get("SANDBOX", str(pathlib.Path(__file__).resolve().parents[1] / "build/sandbox"))


def best_python(world, position, resolution, half_extent, repeats):
    best = float("inf")
    for _ in range(repeats):
        start = time.perf_counter()
        scan = world.face_scan(position, resolution=resolution, half_extent=half_extent)
        scan.occupancy, scan.distance, scan.surface, scan.normal  # the arrays, made
        best = min(best, time.perf_counter() - start)
        del scan  # freed before the next, as the C++ loop's is
    return best


def main():
    rounds = int(sys.argv[1]) if len(sys.argv) > 1 else 7
    world = sandbox.World()
    print("python_scan: the sample level, face scans at (30, -12, 25), "
          "the best of 20 repeats a round, Python and C++ in turns, %d rounds" % rounds)
    print("%-30s %12s %12s %8s" % ("face scan", "C++ ms", "Python ms", "ratio"))
    for resolution, half_extent in ((1.0, 25.0), (0.25, 25.0)):
        ratios = []
        for _ in range(rounds):
            cpp = world._time_face_scan((30, -12, 25), resolution, half_extent, 20)
            python = best_python(world, (30, -12, 25), resolution, half_extent, 20)
            ratios.append(python / cpp)
        n = int(round(2 * half_extent / resolution)) + 1
        ratios.sort()
        print("%-30s %12.3f %12.3f %8.3f" % ("6 x %d x %d, %g m" % (n, n, resolution),
                                             1e3 * cpp, 1e3 * python, ratios[len(ratios) // 2]))
    print("%-30s %12s %12s %8s" % ("render (fixed camera, high), best of 15", "C++ ms", "Python ms",
                                   "ratio"))
    for width, height in ((320, 240), (640, 480)):
        ratios = []
        for _ in range(rounds):
            cpp = world._time_render((-40, -60, 35), width, height, 15)
            python = float("inf")
            for _ in range(15):
                start = time.perf_counter()
                frame = world.render("fixed", (-40, -60, 35), width=width, height=height,
                                     kinds="color,depth")
                frame.color, frame.depth  # the arrays, made
                python = min(python, time.perf_counter() - start)
                del frame  # freed before the next, as the C++ loop's is
            ratios.append(python / cpp)
        ratios.sort()
        print("%-30s %12.3f %12.3f %8.3f" % ("colour and depth, %d x %d" % (width, height),
                                             1e3 * cpp, 1e3 * python, ratios[len(ratios) // 2]))
    lidar = world.lidar_scan((0, 0, 30))
    same = (lidar.range.__array_interface__["data"][0] == lidar._addresses()["range"] and
            lidar.points.__array_interface__["data"][0] == lidar._addresses()["points"])
    print("zero copies: the lidar's range and points arrays are its buffers: %s"
          % ("yes" if same else "NO"))
    print("ratio: the median over the rounds of Python's best over C++'s best (the last round's "
          "times shown)")
    bench_step(rounds)


def flight(ticks, bones):
    """(utime, position, orientation, bone values) a tick: a climbing turn, bending."""
    for k in range(ticks):
        heading = 0.002 * k
        yield (1_000_000 + 10_000 * k, (0.3 * k, -100.0 + 0.2 * k, 40.0 + 0.01 * k),
               (math.cos(heading / 2), 0.0, 0.0, math.sin(heading / 2)),
               [0.2 * math.sin(0.01 * k + b) for b in range(bones)])


def bench_step(rounds, ticks=3000):
    """Lockstep.step() against sandbox run --replay on the same inputs: ticks a second."""
    bones = len(sandbox.World().bones("ELAHA"))
    inputs = list(flight(ticks, bones))
    with tempfile.TemporaryDirectory() as folder:
        log = pathlib.Path(folder) / "inputs.lcmlog"
        with open(log, "wb") as f:
            for k, (utime, position, q, bend) in enumerate(inputs):
                for channel, message in (("ELAHA/BONES", sandbox_msgs.bone_values_t()),
                                         ("ELAHA/POSE", sandbox_msgs.robot_pose_t())):
                    message.utime, message.seq = utime, k
                    if channel.endswith("BONES"):
                        message.num_values, message.values = bones, bend
                    else:
                        message.position, message.orientation = position, q
                    data = message.encode()
                    f.write(struct.pack(">IqqII", 0xEDA1DA01, 2 * k, utime, len(channel), len(data)))
                    f.write(channel.encode() + data)
        encoded = [[("ELAHA/BONES", sandbox.messages.bones_message(bend, utime, k)),
                     ("ELAHA/POSE", sandbox.messages.pose_message(position, q, utime, k))]
                    for k, (utime, position, q, bend) in enumerate(inputs)]
        def replay():
            result = subprocess.run([SANDBOX, "run", "--replay", str(log)], capture_output=True,
                                    text=True, check=True)
            return float(re.search(r"(\d+) ticks in [\d.]+ s \(([\d.]+) Hz\)",
                                   result.stdout).group(2))

        def step():
            with sandbox.Lockstep() as run:
                start = time.perf_counter()
                for utime, position, q, bend in inputs:
                    outputs = run.step(poses={"ELAHA": (position, q)}, bones={"ELAHA": bend},
                                       utime=utime)
                    outputs["ELAHA/STATE"][0].position  # a controller's read of STATE
                return ticks / (time.perf_counter() - start)

        def step_messages():
            with sandbox.Lockstep() as run:
                start = time.perf_counter()
                for messages in encoded:
                    run.step_messages(messages)["ELAHA/STATE"][0].position
                return ticks / (time.perf_counter() - start)

        kinds = [replay, step, step_messages]
        hz = {kind: [] for kind in kinds}
        for k in range(rounds):  # each kind first in turn: drift shared out
            for kind in kinds[k % 3:] + kinds[:k % 3]:
                hz[kind].append(kind())
    for values in hz.values():
        values.sort()
    best_replay, median_replay = hz[replay][-1], hz[replay][len(hz[replay]) // 2]
    print("%-30s %12s %12s %8s %14s" % ("lock-step ticks, %d" % ticks, "replay Hz", "Hz",
                                        "ratio", "median ratio"))
    for label, kind in (("step(): poses, bones; STATE", step),
                        ("step_messages(): encoded", step_messages)):
        print("%-30s %12.0f %12.0f %8.3f %14.3f" % (label, best_replay, hz[kind][-1],
                                                    hz[kind][-1] / best_replay,
                                                    hz[kind][len(hz[kind]) // 2] / median_replay))
    print("step ratio: the best tick rate of %d runs over the best of as many runs of sandbox run "
          "--replay (its own figure) on the same inputs, the kinds taking turns; median ratio: "
          "the same of the median runs. Sensors on; each tick's STATE position read; "
          "step_messages() is given the inputs already encoded" % rounds)


if __name__ == "__main__":
    main()

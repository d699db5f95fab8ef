#!/usr/bin/python3
"""What recording costs the loop: `sandbox run --replay` of the same inputs
(the sample level, 3000 ticks of poses along a circle, its sensors on) without a
recording, with an LCM log and with MCAP (zstd), in turns; each run's
mean tick against the unrecorded run's (target for MCAP: at most 1.05x), the
files' sizes against the LCM log's (target: at most 0.7x); the demo at its
rate (100 Hz, cameras on) without and with a recording (MCAP also holds the
inputs, link frames, the scene and each camera frame written); and the writer
thread's own work a tick (`sandbox convert` of the LCM log, timed).

usage: PYTHONPATH=build/python bench/record_bench.py [ROUNDS]   (default 5)
"""
import math
import os
import pathlib
import re
import statistics
import struct
import subprocess
import sys
import tempfile
import time

from sandbox import sandbox_msgs

SANDBOX = os.environ.get("SANDBOX", str(pathlib.Path(__file__).resolve().parents[1] / "build/sandbox"))
TICKS = 3000


def write_inputs(path):
    """An LCM log (lcm-logger's format) of TICKS poses and bends at 100 Hz."""
    with open(path, "wb") as f:
        number = 0
        for k in range(TICKS):
            utime = 1_000_000 + 10_000 * k
            pose = sandbox_msgs.robot_pose_t()
            heading = 0.002 * k
            pose.utime, pose.seq = utime, k
            pose.position = (30 * math.cos(heading), 30 * math.sin(heading) - 12, 25.0)
            pose.orientation = (math.cos(heading / 2), 0.0, 0.0, math.sin(heading / 2))
            for channel, data in (("ELAHA/POSE", pose.encode()),):
                f.write(struct.pack(">IqqII", 0xEDA1DA01, number, utime, len(channel), len(data)))
                f.write(channel.encode() + data)
                number += 1


def mean_tick_ms(inputs, record):
    args = [SANDBOX, "run", "--replay", str(inputs)] + (["--record", str(record)] if record else [])
    done = subprocess.run(args, capture_output=True, text=True, check=True)
    return float(re.search(r"mean tick ([0-9.]+) ms", done.stdout).group(1))


def demo_tick_ms(folder, record):
    """The demo in-process (100 Hz, cameras writing frames and videos, scans): its mean
    tick, and the sizes of the camera frames it wrote."""
    args = [SANDBOX, "demo", "--in-process", "--duration", "15", "--out", str(folder / "demo")]
    done = subprocess.run(args + (["--record", str(record)] if record else []),
                          capture_output=True, text=True, check=True)
    images = [p.stat().st_size for p in (folder / "demo").rglob("*.jpg") if p.name != "overview.jpg"]
    return float(re.search(r"mean tick ([0-9.]+) ms", done.stdout).group(1)), images


def main():
    rounds = int(sys.argv[1]) if len(sys.argv) > 1 else 5
    with tempfile.TemporaryDirectory(prefix="sandbox-record-bench-") as folder:
        folder = pathlib.Path(folder)
        inputs = folder / "inputs.lcmlog"
        write_inputs(inputs)
        kinds = {"none": None, "LCM log": folder / "run.lcmlog", "MCAP zstd": folder / "run.mcap"}
        ticks = {kind: [] for kind in kinds}
        for _ in range(rounds):
            for kind, record in kinds.items():
                ticks[kind].append(mean_tick_ms(inputs, record))
        print(f"record_bench: the sample level replayed, {TICKS} ticks, sensors on, "
              f"{rounds} rounds in turns (median)")
        print("%-12s %14s %10s %14s %10s" % ("recording", "mean tick ms", "ratio", "bytes", "size"))
        log_bytes = kinds["LCM log"].stat().st_size
        reference = statistics.median(ticks["none"])
        for kind, record in kinds.items():
            tick = statistics.median(ticks[kind])
            size = record.stat().st_size if record else 0
            print("%-12s %14.3f %10.3f %14d %10s" % (
                kind, tick, tick / reference, size,
                "%.3f" % (size / log_bytes) if record else "-"))
        lz4 = folder / "lz4.mcap"
        subprocess.run([SANDBOX, "convert", str(kinds["LCM log"]), str(lz4), "--compression", "lz4"],
                       check=True, capture_output=True)
        print("%-12s %14s %10s %14d %10.3f   (sandbox convert --compression lz4)" % (
            "MCAP lz4", "-", "-", lz4.stat().st_size, lz4.stat().st_size / log_bytes))
        demo = {"none": None, "MCAP zstd": folder / "demo.mcap", "LCM log": folder / "demo.lcmlog"}
        demo_ticks = {kind: [] for kind in demo}
        for _ in range(max(2, rounds // 2)):
            for kind, record in demo.items():
                tick, images = demo_tick_ms(folder, record)
                demo_ticks[kind].append(tick)
                if kind == "MCAP zstd":
                    mcap_images = images  # the frames the last MCAP run wrote, and recorded
        print("the demo at its rate (in-process, 15 s, 100 Hz, cameras and scans on), "
              "%d rounds in turns (median):" % max(2, rounds // 2))
        demo_reference = statistics.median(demo_ticks["none"])
        demo_log_bytes = demo["LCM log"].stat().st_size
        for kind, record in demo.items():
            tick = statistics.median(demo_ticks[kind])
            size = record.stat().st_size if record else 0
            print("%-12s %14.3f %10.3f %14d %10s" % (kind, tick, tick / demo_reference, size,
                                                     "%.3f" % (size / demo_log_bytes) if record else "-"))
        # The MCAP file also holds each camera frame the demo wrote (the LCM log has
        # none), its link frames and scene; its LCM messages alone (its inputs too),
        # with their views, are what `sandbox convert` keeps of it.
        messages = folder / "demo-messages.mcap"
        subprocess.run([SANDBOX, "convert", str(demo["MCAP zstd"]), str(folder / "d.lcmlog")],
                       check=True, capture_output=True)
        subprocess.run([SANDBOX, "convert", str(folder / "d.lcmlog"), str(messages)],
                       check=True, capture_output=True)
        print("  the demo's MCAP holds its %d camera frames (%d bytes of JPEG as written); "
              "its messages alone (outputs and inputs, sandbox convert): %.3f of the LCM log" % (
                  len(mcap_images), sum(mcap_images), messages.stat().st_size / demo_log_bytes))
        print("the writer's thread, a tick (sandbox convert of the LCM log, best of %d):" % rounds)
        for compression in ("zstd", "lz4"):
            best = float("inf")
            for _ in range(rounds):
                start = time.perf_counter()
                subprocess.run([SANDBOX, "convert", str(kinds["LCM log"]), str(folder / "c.mcap"),
                                "--compression", compression], check=True, capture_output=True)
                best = min(best, time.perf_counter() - start)
            print("  %-5s %8.3f ms a tick, %.3f of the unrecorded tick (start-up included)" % (
                compression, 1e3 * best / TICKS, 1e3 * best / TICKS / reference))


if __name__ == "__main__":
    main()

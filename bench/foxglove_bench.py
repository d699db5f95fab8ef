#!/usr/bin/python3
"""What the live Foxglove server costs the loop: the demo at its rate (100 Hz,
in-process, cameras and scans on) without --foxglove and with one client
(Foxglove's npm client, tests/js/foxglove_client.cjs) subscribed to every
channel, in turns: the loop's rate and mean tick against none's (target:
rate within 3%); then the sample level stepped in lock-step as fast as it
goes (sandbox.Lockstep) without the server, with it and no client, and with
one client, where the loop shares 2 cores with the server and the client.

usage: PYTHONPATH=build/python bench/foxglove_bench.py [ROUNDS]   (default 3)
"""
import math
import os
import pathlib
import statistics
import subprocess
import sys
import threading
import time

import sandbox

ROOT = pathlib.Path(__file__).resolve().parents[1]
NODE_PATH = os.environ.get("NODE_PATH", str(ROOT / "build/node/node_modules"))
STEPS = 1500


def pose(k):
    heading = 0.002 * k
    return ((30 * math.cos(heading), 30 * math.sin(heading) - 12, 25.0),
            (math.cos(heading / 2), 0.0, 0.0, math.sin(heading / 2)))


def steps_per_s(kind):
    args = [] if kind == "none" else ["--foxglove", "0"]
    received = [0]
    with sandbox.Lockstep(args=args) as run:
        client = None
        if kind == "one client":
            client = subprocess.Popen(["node", str(ROOT / "tests/js/foxglove_client.cjs"),
                                       run.foxglove_url], stdout=subprocess.PIPE, text=True,
                                      env={**os.environ, "NODE_PATH": NODE_PATH})
            subscribed = threading.Event()

            def read():
                for line in client.stdout:
                    if '"event":"subscribed"' in line and "SCAN_FACE" in line:
                        subscribed.set()
                    received[0] += '"event":"message"' in line
            threading.Thread(target=read, daemon=True).start()
            for k in range(200):  # until the client has subscribed to the scans
                run.step(poses={"ELAHA": pose(k)}, utime=1_000_000 + 10_000 * k)
                if subscribed.wait(0.05):
                    break
        start = time.perf_counter()
        for k in range(STEPS):
            run.step(poses={"ELAHA": pose(k + 200)}, utime=3_000_000 + 10_000 * k)
        rate = STEPS / (time.perf_counter() - start)
        if client:
            time.sleep(0.5)
            client.terminate()
            client.wait()
    return rate, received[0]


def demo(with_client):
    """The demo's loop rate (Hz), mean tick (ms) and the messages the client received."""
    args = [str(ROOT / "build/sandbox"), "demo", "--in-process", "--duration", "15", "--out",
            "/tmp/sandbox-foxglove-bench"] + (["--foxglove", "0"] if with_client else [])
    demo_run = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    client, received, summary = None, [0], ""
    for line in demo_run.stdout:
        if "Foxglove WebSocket server at " in line:
            url = line.split(" at ")[1].strip()
            client = subprocess.Popen(["node", str(ROOT / "tests/js/foxglove_client.cjs"), url],
                                      stdout=subprocess.PIPE, text=True,
                                      env={**os.environ, "NODE_PATH": NODE_PATH})
            threading.Thread(target=lambda: [received.__setitem__(0, received[0] + ('"event":"message"' in l))
                                             for l in client.stdout], daemon=True).start()
        if "ticks in" in line:
            summary = line
    demo_run.wait()
    if client:
        client.terminate()
        client.wait()
    rate = float(summary.split("(")[1].split(" Hz")[0])
    tick = float(summary.split("mean tick ")[1].split(" ms")[0])
    return rate, tick, received[0]


def main():
    rounds = int(sys.argv[1]) if len(sys.argv) > 1 else 3
    runs = {False: [], True: []}
    for _ in range(max(2, rounds - 1)):
        for with_client in (False, True):
            runs[with_client].append(demo(with_client))
    print("foxglove_bench: the demo at its rate (in-process, 15 s, 100 Hz, cameras and scans on), "
          "%d rounds in turns (median)" % max(2, rounds - 1))
    print("%-20s %10s %8s %14s %8s %10s" % ("--foxglove", "rate Hz", "ratio", "mean tick ms", "ratio",
                                           "received"))
    none_rate = statistics.median(r for r, _, _ in runs[False])
    none_tick = statistics.median(t for _, t, _ in runs[False])
    for with_client, name in ((False, "none"), (True, "one client")):
        rate = statistics.median(r for r, _, _ in runs[with_client])
        tick = statistics.median(t for _, t, _ in runs[with_client])
        got = statistics.median(n for _, _, n in runs[with_client])
        print("%-20s %10.2f %8.3f %14.3f %8.3f %10d" % (name, rate, rate / none_rate, tick,
                                                         tick / none_tick, got))
    kinds = ("none", "server, no client", "one client")
    rates = {kind: [] for kind in kinds}
    received = []
    for _ in range(rounds):
        for kind in kinds:
            rate, got = steps_per_s(kind)
            rates[kind].append(rate)
            if kind == "one client":
                received.append(got)
    print(f"the sample level in lock-step, {STEPS} steps a run, sensors on, "
          f"{rounds} rounds in turns (median)")
    print("%-20s %12s %8s" % ("--foxglove", "steps/s", "ratio"))
    reference = statistics.median(rates["none"])
    for kind in kinds:
        rate = statistics.median(rates[kind])
        print("%-20s %12.1f %8.3f" % (kind, rate, rate / reference))
    print("the client received %d messages a run (median; a pose, a face scan and the link "
          "frames a step after it subscribed, and the scene)" % statistics.median(received))


if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""Fly the wing through a loop with the program's own loop (sandbox.Lockstep),
plot a face scan with matplotlib and save the chase camera's frames.

The wing flies a vertical loop (a circle in the x-z plane, pitching with it)
with its wings flexing (BONES), one tick a step at 100 Hz; the run writes the chase
camera's frames (--out, as sandbox run does); the face scanner's downward face
from the lowest point of the loop is plotted as a distance image.

usage: PYTHONPATH=build/python examples/python/fly_wing.py OUT [--ticks N]
"""
import argparse
import json
import math
import pathlib

import matplotlib

matplotlib.use("Agg")  # files only, no display
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import sandbox  # noqa: E402

DOWN = 5  # the face scanner's -Z face


def loop_pose(k, ticks, radius=40.0):
    """A vertical loop: position on a circle in x-z, the wing pitched along it."""
    angle = 2.0 * math.pi * k / ticks
    position = (radius * math.sin(angle), -60.0, 70.0 - radius * math.cos(angle))
    pitch = -angle  # nose along the circle's tangent, climbing first
    return position, (math.cos(pitch / 2), 0.0, math.sin(pitch / 2), 0.0)


def wing_flex(roll):
    """The sample wing's bone values (assets/sample/level.toml's bone map: root, R1-R10,
    L1-L10 with a roll and a pitch each, E1-E3 a pitch each): each wing rolled up
    along its span, the tip most."""
    values = [0.0, 0.0]
    values += [v for i in range(1, 11) for v in (roll * i / 10, 0.0)]
    values += [v for i in range(1, 11) for v in (-roll * i / 10, 0.0)]
    return values + [0.0, 0.0, 0.0]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("out", help="output folder (frames, the plot, flight.json)")
    parser.add_argument("--ticks", type=int, default=600, help="ticks for the loop (100 Hz)")
    args = parser.parse_args()
    if args.ticks < 12:
        parser.error("--ticks must be at least 12")
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    lowest, states = None, []
    with sandbox.Lockstep(args=["--out", str(out / "run"), "--frames", "png"]) as run:
        for k in range(args.ticks):
            position, orientation = loop_pose(k, args.ticks)
            outputs = run.step(poses={"ELAHA": (position, orientation)},
                               bones={"ELAHA": wing_flex(0.3 * math.sin(2.0 * math.pi * k / args.ticks))})
            state = outputs["ELAHA/STATE"][0]
            states.append(state.position.tolist())
            for face in outputs.get("ELAHA/SCAN_FACE", []):
                if face.face == DOWN and (lowest is None or state.position[2] < lowest[0]):
                    lowest = (state.position[2], face)
    summary = run.summary

    # The downward face as a distance image: the sample's distance from the sensor, NaN free.
    z, face = lowest
    n = face.n
    points = face.xyz.reshape(n, n, 3) + face.origin
    distance = np.linalg.norm(points - np.asarray(face.sensor_position), axis=2)
    distance[face.occupancy.reshape(n, n) != 1] = np.nan
    figure, axes = plt.subplots(figsize=(5, 4))
    image = axes.imshow(distance, cmap="viridis", origin="upper")
    figure.colorbar(image, ax=axes, label="distance, m")
    axes.set_title(f"face scanner, down, at z = {z:.1f} m")
    figure.savefig(out / "face_down.png", dpi=80)

    frames = sorted((out / "run").rglob("chase*.png"))
    result = {"ticks": args.ticks, "frames": len(frames), "lowest_z": z,
              "occupied": int(np.sum(face.occupancy == 1)), "positions": states,
              "refused": run.messages}
    (out / "flight.json").write_text(json.dumps(result))
    print(summary.splitlines()[1] if summary else "")
    print(f"{len(frames)} chase frames in {out / 'run'}, the plot in {out / 'face_down.png'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

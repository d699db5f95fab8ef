#!/usr/bin/python3
"""A dataset from the sandbox in Python: N random poses of the wing 5 to 20 m
over the ground of the sample level, each with a chase camera's colour,
depth and segmentation and a face scan around it, written to OUT with an
index (index.csv: one row a sample, its pose and its files).

usage: PYTHONPATH=build/python examples/python/dataset.py OUT [N] [--seed S] [--level LEVEL]
"""
import argparse
import csv
import math
import os
import random

import numpy as np

import sandbox


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out")
    parser.add_argument("n", nargs="?", type=int, default=100)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--level", default=None)
    parser.add_argument("--size", default="320x240", help="image width x height")
    args = parser.parse_args()
    width, height = (int(v) for v in args.size.split("x"))
    world = sandbox.World(args.level)
    robot = world.robots[0]
    rng = random.Random(args.seed)
    os.makedirs(args.out, exist_ok=True)
    with open(os.path.join(args.out, "surfaces.csv"), "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=["id", "kind", "name", "robot", "bone"])
        writer.writeheader()
        writer.writerows(world.surfaces())
    with open(os.path.join(args.out, "index.csv"), "w", newline="") as index:
        rows = csv.writer(index)
        rows.writerow(["sample", "x", "y", "z", "heading_deg", "images", "scan", "hits"])
        for i in range(args.n):
            x, y = rng.uniform(-150, 150), rng.uniform(-150, 150)
            ground = world.ray((x, y, 200), range=400)  # straight down
            z = (ground["point"][2] if ground["hit"] else 0.0) + rng.uniform(5, 20)
            heading = rng.uniform(-180, 180)
            half = math.radians(heading) / 2
            world.set_pose(robot, (x, y, z), (math.cos(half), 0, 0, math.sin(half)))
            frame = world.render("chase", robot=robot, width=width, height=height,
                                 kinds="color,depth,segmentation")
            scan = world.face_scan((x, y, z), (math.cos(half), 0, 0, math.sin(half)),
                                   resolution=1, half_extent=25)
            images = "%04d_images.npz" % i
            np.savez_compressed(os.path.join(args.out, images), color=frame.color,
                                depth=frame.depth, segmentation=frame.segmentation)
            points = scan.points()
            np.save(os.path.join(args.out, "%04d_scan.npy" % i), points)
            hits = int(sum(face.sum() for face in scan.occupancy))
            rows.writerow([i, repr(x), repr(y), repr(z), repr(heading), images,
                           "%04d_scan.npy" % i, hits])
            print("dataset: %d of %d at (%.1f, %.1f, %.1f), %d scan hits"
                  % (i + 1, args.n, x, y, z, hits), flush=True)


if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""A face scan and a render through Python against the same from C++ in one
process (target: at most 1.05x each), and the arrays' data pointers against
the scan's own buffers (zero copies).

usage: PYTHONPATH=build/python bench/python_scan.py [ROUNDS]   (default 7)
"""
import sys
import time

import sandbox


def best_python(world, position, resolution, half_extent, repeats):
    best = float("inf")
    for _ in range(repeats):
        start = time.perf_counter()
        scan = world.face_scan(position, resolution=resolution, half_extent=half_extent)
        scan.occupancy, scan.distance, scan.surface, scan.normal  # the arrays, made
        best = min(best, time.perf_counter() - start)
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
    print("%-30s %12s %12s %8s" % ("render (fixed camera, high)", "C++ ms", "Python ms", "ratio"))
    for width, height in ((320, 240), (640, 480)):
        ratios = []
        for _ in range(rounds):
            cpp = world._time_render((-40, -60, 35), width, height, 5)
            python = float("inf")
            for _ in range(5):
                start = time.perf_counter()
                frame = world.render("fixed", (-40, -60, 35), width=width, height=height,
                                     kinds="color,depth")
                frame.color, frame.depth  # the arrays, made
                python = min(python, time.perf_counter() - start)
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


if __name__ == "__main__":
    main()

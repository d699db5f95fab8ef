"""The sample level's terrain height, restated from its generator
(assets/generators/sample_terrain.h) so that tests check against the formula,
not the program."""
import math


def terrain_height(x, y):
    hill = (x - 110.0) ** 2 + (y - 90.0) ** 2
    lake = (x + 70.0) ** 2 + (y + 60.0) ** 2
    return (14.0 + 6.0 * math.sin(x / 31.0) * math.cos(y / 43.0)
            + 4.0 * math.sin((x - 0.5 * y) / 57.0) + 30.0 * math.exp(-hill / (2.0 * 40.0 ** 2))
            - 14.0 * math.exp(-lake / (2.0 * 45.0 ** 2)))

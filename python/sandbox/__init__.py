"""The sandbox from Python (docs/reference/python.md).

In-process: `World` (a level, its robots posed, scans and renders as numpy
views) and `Lockstep` (the program's loop, one tick a `step()`). Of a running
sandbox: `Client` (its LCM inputs and outputs, without a Python LCM package).
Of files: `read_log` (a `--record` or LCM log into numpy). `decode` turns one
message's bytes into a `Message`.
"""

from ._sandbox import FaceScan, Frame, GroundScan, LevelError, LidarScan, World
from .client import Client
from .lockstep import Lockstep, Outputs
from .log import ChannelLog, Log, read_log
from .messages import Message, decode, message_types

__all__ = [
    "ChannelLog", "Client", "FaceScan", "Frame", "GroundScan", "LevelError", "LidarScan", "Lockstep",
    "Log", "Message", "Outputs", "World", "decode", "message_types", "read_log",
]

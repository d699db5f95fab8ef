"""A client of a running sandbox over LCM, through the project's own link
(no Python LCM package): the inputs published, the outputs received."""

import time

from . import _sandbox
from .messages import (actors_message, bones_message, decode, joints_message, pose_message,
                       utime_of)


_MAX_CHANNEL_BYTES = 63  # LCM_MAX_CHANNEL_NAME_LENGTH (lcm/lcm.h)


class Client:
    """An LCM link to a running sandbox. `url` as the C++ tools take it (empty:
    LCM's default; multicast URLs get a 4 MB receive buffer). Hears every
    channel from its creation on, keeping up to `capacity` messages until
    they are received (then the oldest go, counted in `dropped`).

    `robot` below is the robot's channel prefix (its name unless the manifest
    sets `channel_prefix`); `utime` defaults to the wall clock."""

    def __init__(self, url="", capacity=10000):
        self._link = _sandbox._Link(str(url), int(capacity))
        self._seq = {}

    @property
    def url(self):
        return self._link.url

    @property
    def dropped(self):
        return self._link.dropped

    def _next(self, channel, utime):
        seq = self._seq.get(channel, 0)
        self._seq[channel] = seq + 1
        return (int(time.time() * 1e6) if utime is None else utime_of(utime)), seq

    def publish(self, channel, data):
        """Publishes an encoded message (bytes, or an lcm-gen object with encode())."""
        channel = str(channel)
        if not 0 < len(channel.encode()) <= _MAX_CHANNEL_BYTES or "\0" in channel:
            raise ValueError(f"channel {channel!r}: an LCM channel is 1 to {_MAX_CHANNEL_BYTES} "
                             "bytes, without NUL")
        self._link.publish(channel, data if isinstance(data, bytes) else data.encode())

    def publish_pose(self, robot, position, orientation=(1.0, 0.0, 0.0, 0.0), utime=None):
        """<robot>/POSE: position m, unit quaternion (w, x, y, z), in the robot's pose convention."""
        channel = f"{robot}/POSE"
        self.publish(channel, pose_message(position, orientation, *self._next(channel, utime)))

    def publish_bones(self, robot, values, utime=None):
        """<robot>/BONES: every bone value, flat in bone-map order."""
        channel = f"{robot}/BONES"
        self.publish(channel, bones_message(values, *self._next(channel, utime)))

    def publish_joints(self, robot, values, utime=None):
        """<robot>/JOINTS: {joint name: value} (radians or metres), or every joint in order."""
        channel = f"{robot}/JOINTS"
        self.publish(channel, joints_message(values, *self._next(channel, utime)))

    def publish_actors(self, robot, placements, utime=None):
        """<robot>/ACTORS: {movable actor name: (position, orientation)}, world."""
        channel = f"{robot}/ACTORS"
        self.publish(channel, actors_message(placements, *self._next(channel, utime)))

    def receive(self, timeout=0.0):
        """[(channel, Message)] that arrived, oldest first, waiting up to `timeout`
        s for the first. A message that is not a sandbox type comes as bytes."""
        received = []
        for channel, _, data in self._link.receive(float(timeout)):
            try:
                received.append((channel, decode(data)))
            except ValueError:
                received.append((channel, data))
        return received

    def wait_for(self, channel, timeout=5.0):
        """The first message on `channel` from now on (others received meanwhile
        are dropped); TimeoutError after `timeout` s."""
        end = time.monotonic() + timeout
        while True:
            left = end - time.monotonic()
            if left <= 0:
                raise TimeoutError(f"nothing on {channel} within {timeout} s ({self.url})")
            for name, message in self.receive(min(left, 0.25)):
                if name == channel:
                    return message

"""LCM log files (a `sandbox run --record` log, lcm-logger's) into numpy."""

import numpy as np

from . import _sandbox
from .messages import decode


class ChannelLog:
    """One channel of a log: `lcm_type`, `utime` (int64 array, the log's
    time of each message) and `messages` (decoded, in order)."""

    def __init__(self, name, lcm_type):
        self.name, self.lcm_type = name, lcm_type
        self.messages, self._utime = [], []

    @property
    def utime(self):
        return np.asarray(self._utime, dtype=np.int64)

    def __len__(self):
        return len(self.messages)

    def array(self, field):
        """`field` of every message stacked: shape (messages, ...). ValueError
        naming the field when it is unknown or its shapes differ."""
        if not self.messages:
            return np.empty(0)
        if not hasattr(self.messages[0], field):
            known = ", ".join(self.messages[0].fields())
            raise KeyError(f"{self.name} ({self.lcm_type}) has no field {field!r}; it has {known}")
        values = [getattr(message, field) for message in self.messages]
        shapes = {np.shape(value) for value in values}
        if len(shapes) > 1:
            raise ValueError(f"{self.name}: {field} changes shape between messages {sorted(shapes)}")
        return np.stack([np.asarray(value) for value in values])

    def __repr__(self):
        return f"ChannelLog({self.name!r}, {self.lcm_type}, {len(self)} messages)"


class Log:
    """A log read whole: `channels` {name: ChannelLog}; `events`, the events
    read; `undecoded` {channel: count} of messages that are not sandbox types
    or did not decode; `stopped_early`, empty after a clean end, else where
    and why reading stopped (a log cut short is read up to the break)."""

    def __init__(self, path):
        self.path = str(path)
        self.channels, self.undecoded = {}, {}
        self.events, self.stopped_early = 0, ""

    def __getitem__(self, channel):
        try:
            return self.channels[channel]
        except KeyError:
            raise KeyError(f"{self.path} has no channel {channel!r}; it has "
                           f"{', '.join(sorted(self.channels)) or 'none'}") from None

    def __contains__(self, channel):
        return channel in self.channels

    def __repr__(self):
        return f"Log({self.path!r}, {self.events} events, channels {sorted(self.channels)})"


def read_log(path, channels=None):
    """Reads an LCM log file (`sandbox run --record`, lcm-logger) or an MCAP
    recording (`--record FILE.mcap`) into a `Log`, the messages of `channels`
    only when given (a list of names). A file that is neither raises
    RuntimeError naming it."""
    wanted = None if channels is None else set(channels)
    reader = _sandbox._LogReader(str(path))
    log = Log(path)
    while True:
        event = reader.next()
        if event is None:
            break
        channel, utime, data = event
        if wanted is not None and channel not in wanted:
            continue
        try:
            message = decode(data)
        except ValueError:
            log.undecoded[channel] = log.undecoded.get(channel, 0) + 1
            continue
        channel_log = log.channels.get(channel)
        if channel_log is None:
            channel_log = log.channels[channel] = ChannelLog(channel, message.lcm_type)
        channel_log.messages.append(message)
        channel_log._utime.append(utime)
    log.events, log.stopped_early = reader.events, reader.stopped_early
    return log

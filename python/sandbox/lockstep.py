"""`sandbox run --lockstep` in-process, one tick a step()."""

from collections.abc import Mapping

from . import _sandbox
from .messages import actors_message, joints_message, utime_of


Outputs = _sandbox.Outputs  # what one tick published (lockstep_run.cc)
Mapping.register(Outputs)


class Lockstep:
    """The program's loop (`sandbox run --lockstep`) in this process, ticked by
    `step()`: the level as `sandbox run` loads it (default: the bundled sample
    level), `args` any further `sandbox run` options (`--out DIR`, `--record
    LOG`, `--no-sensors`, `--ticks N`, `--web PORT`, ...). Its outputs are
    those of `sandbox run --replay` on the same inputs. Use it in a `with`
    block, or call `close()`: that ends the run and finishes its files."""

    def __init__(self, level=None, args=(), rate_hz=100.0):
        if isinstance(args, str):
            raise ValueError("args must be a list of sandbox run options, not one string")
        args = [str(arg) for arg in args] + ([str(level)] if level is not None else [])
        if not rate_hz > 0:
            raise ValueError(f"rate_hz must be positive, got {rate_hz!r}")
        self._run = _sandbox._Lockstep(args)
        self._prefix = dict(self._run.robots)
        self.robots = list(self._prefix)
        self.actors = self._run.actors
        self.name = self._run.name
        self.web_url = self._run.web_url or None  # `--web PORT`: the browser view's address
        self.foxglove_url = self._run.foxglove_url or None  # `--foxglove PORT`: ws://...
        self._period_us = round(1e6 / rate_hz)
        self._seq, self._channel_names = {}, {}
        self.summary = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def _channels(self, robot):
        """The robot's input channels, {kind: name}; KeyError for an unknown robot."""
        channels = self._channel_names.get(robot)
        if channels is None:
            if robot not in self._prefix:
                raise KeyError(f"no robot {robot!r}; the level has "
                               f"{', '.join(self.robots) or 'none'}")
            channels = self._channel_names[robot] = {
                kind: f"{self._prefix[robot]}/{kind}" for kind in ("JOINTS", "ACTORS")}
        return channels

    def _seq_of(self, channel):
        seq = self._seq.get(channel, 0)
        self._seq[channel] = seq + 1
        return seq

    def step(self, poses=None, bones=None, joints=None, actors=None, utime=None):
        """Runs one tick on these inputs and returns its `Outputs`.

        poses: {robot: (position, orientation)} (or just a position), in each
        robot's pose convention; a robot left out keeps its last pose, re-sent
        at this tick's time (every tick needs a pose: lock-step time is the
        poses' utime). bones: {robot: values in bone-map order}; joints:
        {robot: {joint: value} or every value}; actors: {movable actor:
        (position, orientation)}, world. utime: this tick's time in
        microseconds (default: the last plus one period of rate_hz)."""
        encoded = []
        if joints or actors:  # encoded here; bone values and poses are, in C++
            if utime is None:
                last = self._run.last_utime
                utime = 0 if last is None else last + self._period_us
            utime = utime_of(utime)
            if joints:
                for robot, value in joints.items():
                    channel = self._channels(robot)["JOINTS"]
                    encoded.append((channel, joints_message(value, utime, self._seq_of(channel))))
            if actors:
                channel = self._channels(self.robots[0])["ACTORS"]
                encoded.append((channel, actors_message(actors, utime, self._seq_of(channel))))
        return self._run.step_robots(poses, bones, encoded, utime, self._period_us)

    def step_messages(self, inputs):
        """Runs one tick on messages encoded by the caller, `[(channel, bytes)]`
        in arrival order (the fast path: nothing encoded here, no last pose
        re-sent); returns its `Outputs`."""
        return self._run.step(inputs if isinstance(inputs, list) else list(inputs))

    @property
    def messages(self):
        """What the run has said on its error stream (rejected inputs, warnings)."""
        return self._run.messages

    def close(self):
        """Ends the run (files finished); returns and keeps its summary (`summary`)."""
        if self.summary is None:
            self.summary = self._run.close()
        return self.summary

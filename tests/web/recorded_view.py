#!/usr/bin/python3
"""A recorded flight in the browser (sandbox view LOG) in a real headless Chromium.

Writes a 20 s flight's inputs with fly_wing --write-log, starts `sandbox view`
on it, opens the page through chromedriver and drives its player: a jump to a
tick shows that tick's pose (the log's own POSE message of that index, read
here from the file: lock-step, tick N is the N-th pose), the slider moved by
hand jumps there too, play moves the ticks on at about the chosen speed, pause
holds them; a bad command is refused and counted.

usage: recorded_view.py SANDBOX FLY_WING
"""
import os
import re
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from browser_view import Chromium, served, wait_for  # noqa: E402


def poses(log):
    """The positions of the log's POSE messages, in order (robot_pose_t:
    fingerprint, utime, seq, position[3], orientation[4], big-endian)."""
    out = []
    with open(log, "rb") as f:
        data = f.read()
    at = 0
    while at + 28 <= len(data):
        sync, _, _, channel_len, data_len = struct.unpack_from(">IqqII", data, at)
        assert sync == 0xEDA1DA01, "not an LCM log event at byte %d" % at
        at += 28
        channel = data[at:at + channel_len].decode()
        message = data[at + channel_len:at + channel_len + data_len]
        at += channel_len + data_len
        if channel.endswith("/POSE"):
            out.append(struct.unpack_from(">3d", message, 8 + 16))
    return out


def main():
    sandbox, fly_wing = sys.argv[1], sys.argv[2]
    work = tempfile.mkdtemp(prefix="sandbox-recorded-")
    log = os.path.join(work, "flight.lcmlog")
    subprocess.run([fly_wing, "--write-log", log, "--duration", "20", "--rate", "100"],
                   check=True, stdout=subprocess.DEVNULL)
    expected = poses(log)
    assert len(expected) == 2000, len(expected)
    view = subprocess.Popen([sandbox, "view", log, "--web", "0"], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True)
    match = served(view, r"(\d+) ticks of .* at (http://\S+)")
    assert int(match.group(1)) == len(expected), match.group(0)
    try:
        with Chromium() as browser:
            play(browser, match.group(2), expected)
    finally:
        view.send_signal(signal.SIGINT)
        rest, _ = view.communicate(timeout=60)
        shutil.rmtree(work, ignore_errors=True)
    match = re.search(r"commands: (\d+) taken, (\d+) refused", rest)
    assert match and int(match.group(1)) == 7 and int(match.group(2)) == 1, rest
    print("sandbox view: " + match.group(0))


def play(browser, url, expected):
    """The player driven as a user would (see the top)."""
    browser.go(url)
    wait_for("the level and the player", lambda: browser.run(
        "const v = window.sandboxView; return v.levelLoaded && v.recordedTicks && v.tick >= 0"))

    def shown():
        return browser.run("const v = window.sandboxView; return [v.tick, v.robots.ELAHA.p, "
                           "Number(document.getElementById('slider').value)]")

    def seek_to(tick, by_hand):
        if by_hand:  # the slider dragged and let go
            browser.run("const s = document.getElementById('slider'); s.value = %d; "
                        "s.dispatchEvent(new Event('input')); "
                        "s.dispatchEvent(new Event('change'))" % tick)
        else:
            browser.run("window.sandboxControl.player({seek: %d})" % tick)
        return wait_for("tick %d shown" % tick, lambda: (lambda s: s if s[0] == tick else None)(
            shown()))

    checked = 0
    for tick, by_hand in ((1234, False), (17, True), (1999, False), (0, True), (977, True)):
        at, p, slider = seek_to(tick, by_hand)
        error = max(abs(a - b) for a, b in zip(p, expected[tick]))
        assert error < 1e-6, (tick, p, expected[tick])
        assert slider == tick, (tick, slider)
        checked += 1
    # Play at 4x: about 400 ticks a second of wall time (100 Hz log).
    browser.run("window.sandboxControl.player({speed: 4, play: true})")
    start = time.monotonic()
    wait_for("playing", lambda: browser.run("return window.sandboxView.playing"))
    first = shown()[0]
    time.sleep(2.0)
    second = shown()[0]
    elapsed = time.monotonic() - start
    assert second > first + 100, (first, second)
    assert second - 977 <= 4 * 100 * elapsed + 50, (second, elapsed)
    browser.run("window.sandboxControl.player({play: false})")
    wait_for("paused", lambda: not browser.run("return window.sandboxView.playing"))
    time.sleep(0.3)
    held = shown()[0]
    time.sleep(1.0)
    assert shown()[0] == held, "paused, yet moved on"
    browser.run("window.sandboxControl.player({seek: -5})")  # refused, counted
    errors = browser.script_errors()
    assert not errors, errors
    print("recorded view: %d jumps (2 by command, 3 by the slider) showed the log's pose "
          "at each tick; 4x play moved %d ticks in %.1f s; pause held tick %d"
          % (checked, second - first, elapsed, held))


if __name__ == "__main__":
    main()

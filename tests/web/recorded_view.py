#!/usr/bin/python3
"""A recorded flight in the browser (sandbox view LOG) in a real headless Chromium.

Writes a 20 s flight's inputs with fly_wing --write-log, starts `sandbox view`
on it, opens the page through chromedriver and drives its player: a jump to a
tick shows that tick's pose (the log's own POSE message of that index, read
here from the file: lock-step, tick N is the N-th pose), the slider moved by
hand jumps there too, play moves the ticks on at about the chosen speed, pause
holds them; a bad command is refused and counted. Then the same flight's
`sandbox run --replay --record` log (STATE messages, no POSE): `sandbox view`
replays its states as inputs, and its ticks show the flight's poses again.

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


def serve(sandbox, log, lines=None):
    """`sandbox view LOG` serving: the process and its line's match (ticks, url)."""
    view = subprocess.Popen([sandbox, "view", log, "--web", "0"], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True)
    return view, served(view, r"(\d+) ticks of .* at (http://\S+)", lines)


def finish(view):
    view.send_signal(signal.SIGINT)
    rest, _ = view.communicate(timeout=60)
    return rest


def main():
    sandbox, fly_wing = sys.argv[1], sys.argv[2]
    work = tempfile.mkdtemp(prefix="sandbox-recorded-")
    try:
        log = os.path.join(work, "flight.lcmlog")
        subprocess.run([fly_wing, "--write-log", log, "--duration", "20", "--rate", "100"],
                       check=True, stdout=subprocess.DEVNULL)
        expected = poses(log)
        assert len(expected) == 2000, len(expected)
        view, match = serve(sandbox, log)
        try:
            assert int(match.group(1)) == len(expected), match.group(0)
            with Chromium() as browser:
                play(browser, match.group(2), expected)
        finally:
            rest = finish(view)
        match = re.search(r"commands: (\d+) taken, (\d+) refused", rest)
        assert match and int(match.group(1)) == 7 and int(match.group(2)) == 1, rest
        print("sandbox view: " + match.group(0))

        recorded = os.path.join(work, "recorded.lcmlog")
        subprocess.run([sandbox, "run", "--replay", log, "--record", recorded, "--frames",
                        "none"], check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        assert not poses(recorded), "a --record log holds no POSE"
        replayed = []
        view, match = serve(sandbox, recorded, replayed)
        try:
            assert int(match.group(1)) == len(expected), match.group(0)
            with Chromium() as browser:
                browser.go(match.group(2))
                wait_for_player(browser)
                for tick in (1500, 3):
                    assert browser.run(
                        "return window.sandboxControl.player({seek: %d})" % tick)
                    p = wait_for("tick %d of the recorded log" % tick, lambda: browser.run(
                        "const v = window.sandboxView; return v.tick === %d && v.robots.ELAHA "
                        "&& v.robots.ELAHA.p" % tick))
                    error = max(abs(a - b) for a, b in zip(p, expected[tick]))
                    assert error < 1e-6, (tick, p, expected[tick])
        finally:
            rest = finish(view)
        replayed = "".join(replayed)
        assert "its states are replayed as ELAHA's POSE and BONES" in replayed, replayed
        print("sandbox view of the --record log: 2 jumps showed the flight's pose at each tick")
    finally:
        shutil.rmtree(work, ignore_errors=True)


def wait_for_player(browser):
    """Until the page shows the level and a tick of the recording (it is connected: its
    player commands are sent, not dropped)."""
    wait_for("the level and the player", lambda: browser.run(
        "const v = window.sandboxView; return v.levelLoaded && v.recordedTicks && v.tick >= 0"))


def play(browser, url, expected):
    """The player driven as a user would (see the top)."""
    browser.go(url)
    wait_for_player(browser)

    def shown():
        return browser.run("const v = window.sandboxView; return [v.tick, v.robots.ELAHA.p, "
                           "Number(document.getElementById('slider').value)]")

    def seek_to(tick, by_hand):
        if by_hand:  # the slider dragged and let go
            browser.run("const s = document.getElementById('slider'); s.value = %d; "
                        "s.dispatchEvent(new Event('input')); "
                        "s.dispatchEvent(new Event('change'))" % tick)
        else:
            assert browser.run("return window.sandboxControl.player({seek: %d})" % tick)
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
    assert browser.run("return window.sandboxControl.player({speed: 4, play: true})")
    start = time.monotonic()
    wait_for("playing", lambda: browser.run("return window.sandboxView.playing"))
    first = shown()[0]
    time.sleep(2.0)
    second = shown()[0]
    elapsed = time.monotonic() - start
    assert second > first + 100, (first, second)
    assert second - 977 <= 4 * 100 * elapsed + 50, (second, elapsed)
    assert browser.run("return window.sandboxControl.player({play: false})")
    wait_for("paused", lambda: not browser.run("return window.sandboxView.playing"))
    time.sleep(0.3)
    held = shown()[0]
    time.sleep(1.0)
    assert shown()[0] == held, "paused, yet moved on"
    # Sent, and refused and counted by the sandbox.
    assert browser.run("return window.sandboxControl.player({seek: -5})")
    errors = browser.script_errors()
    assert not errors, errors
    print("recorded view: %d jumps (2 by command, 3 by the slider) showed the log's pose "
          "at each tick; 4x play moved %d ticks in %.1f s; pause held tick %d"
          % (checked, second - first, elapsed, held))


if __name__ == "__main__":
    main()

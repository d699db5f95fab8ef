#!/usr/bin/python3
"""The browser view's page in headless Chromium (software GL, as a server
without a GPU would show it to a laptop's browser here): on the formation
level (three wings, assets/formation), each flown by fly_wing over LCM, how
long until the page draws its first frame with the level, and its frame rate;
against the same page with the robots not flying (hidden: the level alone).
For scripts/bench-browser (inside a private network namespace); asserts
nothing.

usage: browser_page.py SANDBOX FLY_WING LEVEL [SECONDS]
"""
import os
import signal
import subprocess
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "web"))
from browser_view import Chromium, served, wait_for  # noqa: E402


def measure(sandbox, fly_wing, level, seconds, flying):
    started = time.monotonic()
    run = subprocess.Popen([sandbox, "run", level, "--web", "0", "--duration", str(seconds + 60)],
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    url = served(run).group(1)
    serving_s = time.monotonic() - started
    pilots = [subprocess.Popen([fly_wing, "--slot", slot, "--duration", str(seconds + 50)],
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
              for slot in (("wing", "left", "right") if flying else ())]
    try:
        with Chromium() as browser:
            return page_figures(browser, url, 3 if flying else 0, seconds, serving_s)
    finally:
        for pilot in pilots:
            pilot.kill()
            pilot.wait()
        run.send_signal(signal.SIGINT)
        run.communicate(timeout=60)


def page_figures(browser, url, robots, seconds, serving_s):
    """(serving, first frame, frames a second) of the page once `robots` fly."""
    browser.go(url)
    wait_for("the level and %d robots" % robots, lambda: browser.run(
        "const v = window.sandboxView; return v.firstFrameMs !== null && "
        "Object.values(v.robots).filter((r) => r.has_pose).length >= %d" % robots))
    first_ms = browser.run("return window.sandboxView.firstFrameMs")
    a = browser.run("return window.sandboxView.framesDrawn")
    time.sleep(seconds)
    b = browser.run("return window.sandboxView.framesDrawn")
    return serving_s, first_ms, (b - a) / seconds


def main():
    sandbox, fly_wing, level = sys.argv[1:4]
    seconds = float(sys.argv[4]) if len(sys.argv) > 4 else 10.0
    print("browser_page: %s, headless Chromium (SwiftShader), %.0f s a run, 3 rounds" % (
        os.path.basename(os.path.dirname(level)), seconds))
    print("%-34s %12s %16s %10s" % ("", "serving (s)", "first frame (ms)", "frames/s"))
    ratios = []
    for round_ in (1, 2, 3):
        alone = measure(sandbox, fly_wing, level, seconds, False)
        three = measure(sandbox, fly_wing, level, seconds, True)
        for name, m in (("level alone (round %d)" % round_, alone),
                        ("three wings flying (round %d)" % round_, three)):
            print("%-34s %12.2f %16.0f %10.2f" % (name, *m))
        ratios.append(three[2] / alone[2])
    print("frame rate with three wings / level alone: %s" % ", ".join("%.2f" % r for r in ratios))


if __name__ == "__main__":
    main()

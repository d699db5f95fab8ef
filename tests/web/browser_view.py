#!/usr/bin/python3
"""The browser view (sandbox run --web) in a real headless Chromium.

Starts `sandbox demo --web 0` (the wing flown in-process over memq://), drives
Debian's chromium through chromedriver (the WebDriver protocol, over HTTP with
the standard library) to the printed address, and checks what a user would
see: the level drawn (the sample level's grass covers much of the screenshot),
states arriving with increasing ticks, the wing posed and moving, the robot's
status. Prints the time to the first drawn frame and the page's frame rate.

usage: browser_view.py SANDBOX
"""
import base64
import io
import json
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
import urllib.error
import urllib.request

from PIL import Image


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_for(what, check, seconds=60.0):
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        value = check()
        if value:
            return value
        time.sleep(0.2)
    raise AssertionError("timed out waiting for " + what)


class WebDriver:
    def __init__(self, port):
        self.base = "http://127.0.0.1:%d" % port
        options = {"args": ["--headless=new", "--no-sandbox", "--use-gl=angle",
                            "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
                            "--window-size=800,500", "--disable-dev-shm-usage"],
                   "binary": "/usr/bin/chromium"}
        reply = self.call("POST", "/session", {"capabilities": {"alwaysMatch": {
            "browserName": "chrome", "goog:chromeOptions": options}}})
        self.session = reply["sessionId"]

    def call(self, method, path, body=None):
        data = None if body is None else json.dumps(body).encode()
        request = urllib.request.Request(self.base + path, data=data, method=method,
                                         headers={"Content-Type": "application/json"})
        try:
            with urllib.request.urlopen(request, timeout=120) as response:
                return json.loads(response.read())["value"]
        except urllib.error.HTTPError as error:
            raise AssertionError("WebDriver %s %s: %s" % (method, path, error.read()[:2000]))

    def go(self, url):
        self.call("POST", "/session/%s/url" % self.session, {"url": url})

    def run(self, script):
        return self.call("POST", "/session/%s/execute/sync" % self.session,
                         {"script": script, "args": []})

    def screenshot(self):
        png = base64.b64decode(self.call("GET", "/session/%s/screenshot" % self.session))
        return Image.open(io.BytesIO(png)).convert("RGB")

    def quit(self):
        self.call("DELETE", "/session/%s" % self.session)


def main():
    sandbox = sys.argv[1]
    out = tempfile.mkdtemp(prefix="sandbox-browser-")
    demo = subprocess.Popen([sandbox, "demo", "--web", "0", "--duration", "120", "--out", out],
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    lines = []
    url = None
    while url is None:
        line = demo.stdout.readline()
        if not line:
            raise AssertionError("the demo ended before serving:\n" + "".join(lines))
        lines.append(line)
        match = re.search(r"browser view at (http://\S+)", line)
        url = match.group(1) if match else None
    driver_port = free_port()
    # In a process group of its own: the browser it starts goes with it.
    driver = subprocess.Popen(["/usr/bin/chromedriver", "--port=%d" % driver_port],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                              start_new_session=True)
    browser = None
    try:
        wait_for("chromedriver", lambda: _answers(driver_port))
        browser = WebDriver(driver_port)
        started = time.monotonic()
        browser.go(url)
        view = wait_for("the level and a posed wing", lambda: _ready(browser))
        first = browser.run("return window.sandboxView")
        time.sleep(3.0)
        later = browser.run("return window.sandboxView")
        seconds = 3.0
        # States arrive and move on; the wing flies (the example flight is at
        # 20 m/s and more: metres in 3 s).
        assert later["tick"] > first["tick"] + 10, (first["tick"], later["tick"])
        assert later["received"] > first["received"] + 10
        assert later["states"] > first["states"]
        a, b = first["robots"]["ELAHA"]["p"], later["robots"]["ELAHA"]["p"]
        moved = sum((x - y) ** 2 for x, y in zip(a, b)) ** 0.5
        assert moved > 5.0, "the wing moved %.2f m in 3 s" % moved
        assert later["robots"]["ELAHA"]["has_pose"]
        assert later["robots"]["ELAHA"]["rejected"] == 0
        # The level is drawn: the sample level's ground is grass, green over red and blue.
        image = browser.screenshot()
        pixels = list(image.getdata())
        green = sum(1 for r, g, b in pixels if g > r + 10 and g > b + 10) / len(pixels)
        assert green > 0.15, "green (grass) covers %.1f%% of the screenshot" % (100 * green)
        fps = (later["framesDrawn"] - first["framesDrawn"]) / seconds
        print("browser view: level and first frame %.0f ms after the page opened (page's own "
              "clock), %.1f frames/s in headless Chromium (software GL), %d states in %.0f s, "
              "wing moved %.1f m, grass %.0f%% of the screenshot"
              % (later["firstFrameMs"], fps, later["states"] - first["states"], seconds, moved,
                 100 * green))
    finally:
        if browser is not None:
            browser.quit()
        os.killpg(driver.pid, signal.SIGKILL)
        driver.wait()
        demo.send_signal(signal.SIGINT)
        rest, _ = demo.communicate(timeout=120)
    shutil.rmtree(out, ignore_errors=True)
    summary = re.search(r"browser view: (\d+) clients", rest)
    assert summary and int(summary.group(1)) >= 1, rest
    print("sandbox: " + summary.group(0))


def _answers(port):
    try:
        with urllib.request.urlopen("http://127.0.0.1:%d/status" % port, timeout=2) as reply:
            return json.loads(reply.read())["value"]["ready"]
    except OSError:
        return False


def _ready(browser):
    view = browser.run("return window.sandboxView")
    robot = view["robots"].get("ELAHA") if view else None
    return view if view and view["levelLoaded"] and robot and robot["has_pose"] else None


if __name__ == "__main__":
    main()

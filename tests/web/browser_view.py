#!/usr/bin/python3
"""The browser view (sandbox run --web) in a real headless Chromium.

Starts `sandbox demo --web 0` (the wing flown in-process over memq://), drives
Debian's chromium through chromedriver (the WebDriver protocol, over HTTP with
the standard library) to the printed address, and checks what a user would
see: the level drawn (the sample level's grass covers much of the screenshot),
states arriving with increasing ticks, the wing posed and moving, the robot's
status. Then holds the page at one state and compares the robot as the browser
skins and draws it with the sandbox's own render (OSMesa, `sandbox render`
with the same robot pose, bone values and camera): the robot's pixels overlap
with an intersection over union of at least 0.95. Prints the time to the
first drawn frame, the page's frame rate and the overlap.

usage: browser_view.py SANDBOX
"""
import base64
import csv
import io
import json
import math
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

    def script_errors(self):
        """The page's uncaught errors and failed loads so far (Chrome's log)."""
        entries = self.call("POST", "/session/%s/se/log" % self.session, {"type": "browser"})
        return [e["message"] for e in entries if e["level"] == "SEVERE"]

    def quit(self):
        self.call("DELETE", "/session/%s" % self.session)


class Chromium:
    """chromedriver and the headless Chromium it drives, as a context: the
    WebDriver session on entry; on exit both are ended (chromedriver in a
    process group of its own, so that the browser goes with it)."""

    def __enter__(self):
        port = free_port()
        self.driver = subprocess.Popen(["/usr/bin/chromedriver", "--port=%d" % port],
                                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                       start_new_session=True)
        self.browser = None
        try:
            wait_for("chromedriver", lambda: _answers(port))
            self.browser = WebDriver(port)
        except BaseException:
            self.__exit__(None, None, None)
            raise
        return self.browser

    def __exit__(self, *exc):
        if self.browser is not None:
            self.browser.quit()
        os.killpg(self.driver.pid, signal.SIGKILL)
        self.driver.wait()
        return False


def served(process, pattern=r"browser view at (http://\S+)", lines=None):
    """The match of `pattern` in the lines `process` prints (its stdout, text)
    up to the first that has it, those lines appended to `lines`;
    AssertionError with them when it ends first."""
    lines = [] if lines is None else lines
    while True:
        line = process.stdout.readline()
        if not line:
            raise AssertionError("ended before serving:\n" + "".join(lines))
        lines.append(line)
        match = re.search(pattern, line)
        if match:
            return match


def main():
    sandbox = sys.argv[1]
    out = tempfile.mkdtemp(prefix="sandbox-browser-")
    demo = subprocess.Popen([sandbox, "demo", "--web", "0", "--web-control", "--duration", "300",
                             "--out", out],
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    url = served(demo).group(1)
    try:
        with Chromium() as browser:
            check_demo(browser, sandbox, url, out)
    finally:
        demo.send_signal(signal.SIGINT)
        rest, _ = demo.communicate(timeout=120)
    shutil.rmtree(out, ignore_errors=True)
    summary = re.search(r"browser view: (\d+) clients", rest)
    assert summary and int(summary.group(1)) >= 1, rest
    commands = re.search(r"commands: (\d+) taken, (\d+) refused", rest)
    assert commands and commands.group(1) == "3" and commands.group(2) == "0", rest
    print("sandbox: " + summary.group(0))


def check_demo(browser, sandbox, url, out):
    """What a user sees of the demo, each part checked (see the top)."""
    browser.go(url)
    wait_for("the level and a posed wing", lambda: _ready(browser))
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
    # Its inputs a second (pose and bones at 100 Hz from the example model).
    rate = wait_for("the wing's input rate", lambda: browser.run(
        "return window.sandboxView.robots.ELAHA.inputsPerSecond") or None)
    assert rate > 20, rate
    # The level is drawn: the sample level's ground is grass, green over red and blue.
    image = browser.screenshot()
    pixels = list(image.getdata())
    green = sum(1 for r, g, b in pixels if g > r + 10 and g > b + 10) / len(pixels)
    assert green > 0.15, "green (grass) covers %.1f%% of the screenshot" % (100 * green)
    fps = (later["framesDrawn"] - first["framesDrawn"]) / seconds
    print("browser view: level and first frame %.0f ms after the page's navigation (its own "
          "clock), %.1f frames/s in headless Chromium (software GL), %d states in %.0f s, "
          "wing moved %.1f m, grass %.0f%% of the screenshot"
          % (later["firstFrameMs"], fps, later["states"] - first["states"], seconds, moved,
             100 * green))
    checked, worst, picked = sample_checks(browser)
    print("browser view: %d of the face scanner's hits checked against the level model the "
          "page draws: each within %.1e m of its surfaces; a click picks sample %s"
          % (checked, worst, picked))
    camera_note = camera_frame(browser, out)
    print("browser view: " + camera_note)
    print("browser view: " + steer_trailing_camera(browser))
    iou, tick, pixels = robot_overlap(browser, sandbox, out)
    errors = browser.script_errors()
    assert not errors, errors
    print("browser view: the skinned wing at tick %d overlaps OSMesa's render from the same "
          "camera with IoU %.3f (%d robot pixels)" % (tick, iou, pixels))
    assert iou >= 0.95, "IoU %.3f" % iou


def matrix_from_quaternion(q):
    w, x, y, z = q
    n = math.sqrt(w * w + x * x + y * y + z * z)
    w, x, y, z = w / n, x / n, y / n, z / n
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]]


def quaternion_from_matrix(m):
    trace = m[0][0] + m[1][1] + m[2][2]
    if trace > 0:
        s = 2 * math.sqrt(1 + trace)
        return [s / 4, (m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s]
    i = max(range(3), key=lambda k: m[k][k])
    j, k = (i + 1) % 3, (i + 2) % 3
    s = 2 * math.sqrt(1 + m[i][i] - m[j][j] - m[k][k])
    q = [0.0] * 4
    q[0] = (m[k][j] - m[j][k]) / s
    q[1 + i] = s / 4
    q[1 + j] = (m[j][i] + m[i][j]) / s
    q[1 + k] = (m[k][i] + m[i][k]) / s
    return q


def pose_argument(p, m):
    """X,Y,Z,ROLL,PITCH,YAW (degrees, yaw-pitch-roll about z, y, x) of a pose."""
    roll = math.atan2(m[2][1], m[2][2])
    pitch = math.asin(max(-1.0, min(1.0, -m[2][0])))
    yaw = math.atan2(m[1][0], m[0][0])
    return ",".join("%.9g" % v for v in list(p) + [math.degrees(roll), math.degrees(pitch),
                                                   math.degrees(yaw)])


SAMPLES_ON_SURFACES = """
const T = window.sandboxControl.three, level = window.sandboxControl.levelModel();
const meshes = [];
level.traverse((o) => { if (o.isMesh && !o.isSkinnedMesh) meshes.push(o); });
const cloud = window.sandboxControl.scene.getObjectByName('samples:ELAHA/scanner');
const pos = cloud.geometry.getAttribute('position'), hit = cloud.userData.hit;
const surface = cloud.userData.surface, o = cloud.position;
const rc = new T.Raycaster();
const dirs = [new T.Vector3(1, 0, 0), new T.Vector3(0, 1, 0), new T.Vector3(0, 0, 1)];
let worst = 0, checked = 0, first = -1, noSurface = 0;
for (let i = 0; i < hit.length && checked < 60; i += 1) {
  if (!hit[i]) continue;
  if (first < 0) first = i;
  if (surface[i] === 0) noSurface += 1;
  const p = new T.Vector3(pos.getX(i) + o.x, pos.getY(i) + o.y, pos.getZ(i) + o.z);
  let best = Infinity;
  for (const d of dirs) {
    rc.set(p.clone().addScaledVector(d, -2), d);
    rc.far = 4;
    for (const h of rc.intersectObjects(meshes)) best = Math.min(best, h.point.distanceTo(p));
  }
  worst = Math.max(worst, best);
  checked += 1;
}
// A click where a hit sample shows picks a sample there.
const p = new T.Vector3(pos.getX(first) + o.x, pos.getY(first) + o.y, pos.getZ(first) + o.z);
const ndc = p.clone().project(window.sandboxControl.camera);
const picked = window.sandboxControl.pick(ndc.x, ndc.y);
// What it says is that sample's, and the sample is under the click.
let consistent = false, off = null;
if (picked) {
  const k = picked.index, q = new T.Vector3(...picked.p);
  consistent = picked.hit === (hit[k] === 1) && picked.surface === surface[k] &&
               q.distanceTo(new T.Vector3(pos.getX(k) + o.x, pos.getY(k) + o.y, pos.getZ(k) + o.z)) < 1e-3;
  const r = q.clone().project(window.sandboxControl.camera);
  off = Math.hypot(r.x - ndc.x, r.y - ndc.y);
}
return { checked, worst, noSurface, inView: Math.abs(ndc.x) < 1 && Math.abs(ndc.y) < 1,
         picked, consistent, off };
"""


def sample_checks(browser):
    """The face scanner's samples as the page draws them: each hit lies on the
    level's surfaces (the page's own model of it, by three.js's ray casting:
    independent of the sandbox's ray caster) and names a surface; a click on
    one picks it. Returns (hits checked, farthest from a surface, picked)."""
    wait_for("the face scanner's hits", lambda: _samples(browser), seconds=100.0)
    browser.run("window.sandboxControl.hold(true)")
    drawn = browser.run("return window.sandboxView.framesDrawn")
    wait_for("a frame of the held state",
             lambda: browser.run("return window.sandboxView.framesDrawn") > drawn + 1)
    result = browser.run(SAMPLES_ON_SURFACES)
    browser.run("window.sandboxControl.hold(false)")
    assert result["checked"] >= 10, result
    assert result["worst"] < 0.02, result
    assert result["noSurface"] == 0, result
    if result["inView"]:
        picked = result["picked"]
        assert picked and result["consistent"] and result["off"] < 0.05, result
        return result["checked"], result["worst"], "#%d (%s)" % (
            picked["index"], picked["surfaceName"] or ("hit" if picked["hit"] else "free"))
    return result["checked"], result["worst"], "(none in view)"


def _samples(browser):
    view = browser.run("return window.sandboxView")
    samples = (view.get("samples") or {}).get("ELAHA/scanner")
    return view if samples and samples["hits"] >= 10 else None


def thumbnail(image, box=None):
    """A 32 x 24 grey thumbnail's pixel values (of `box` when given)."""
    if box:
        image = image.crop(box)
    return list(image.convert("L").resize((32, 24), Image.BILINEAR).getdata())


def camera_frame(browser, out):
    """The chase camera's latest frame as the page shows it: the very JPEG the
    frame writer wrote for that tick (its size), drawn upright in the
    camera's frustum: looked at from the camera's own pose, the page shows
    the frame (thumbnails within 25 grey levels on average; the frame upside
    down is farther)."""
    wait_for("the chase camera's frame", lambda: browser.run(
        "const c = window.sandboxView.cameras.chase; return c && c.decoded"), seconds=100.0)
    browser.run("window.sandboxControl.hold(true)")
    frame = browser.run("return window.sandboxView.cameras.chase")
    written = os.path.join(out, "chase", "chase_%06d.jpg" % frame["tick"])
    assert os.path.getsize(written) == frame["bytes"], (written, frame["bytes"])
    browser.run("window.sandboxControl.setCamera(%s, %s, %f); window.sandboxControl.cameraOnly('chase')"
                % (frame["p"], frame["q"], frame["fovDeg"]))
    drawn = browser.run("return window.sandboxView.framesDrawn")
    wait_for("a frame through the camera",
             lambda: browser.run("return window.sandboxView.framesDrawn") > drawn + 1)
    shot = browser.screenshot()
    if os.environ.get("SANDBOX_BROWSER_SHOTS"):
        shot.save(os.path.join(os.environ["SANDBOX_BROWSER_SHOTS"], "through_chase.png"))
    width, height = shot.size
    shown_width = height * frame["width"] / frame["height"]  # the page's aspect is wider
    box = (round((width - shown_width) / 2), 0, round((width + shown_width) / 2), height)
    page = thumbnail(shot, box)
    image = Image.open(written)
    upright = sum(abs(a - b) for a, b in zip(page, thumbnail(image))) / len(page)
    flipped = sum(abs(a - b) for a, b in zip(page, thumbnail(image.transpose(Image.FLIP_TOP_BOTTOM)))) / len(page)
    browser.run("window.sandboxControl.cameraOnly(null); window.sandboxControl.setCamera(null); "
                "window.sandboxControl.hold(false)")
    assert upright < 25 and upright < flipped, (upright, flipped)
    return ("the chase camera's frame of tick %d (%d bytes, the writer's file) drawn in its "
            "frustum: %.1f grey levels from the file seen through it (%.1f upside down)"
            % (frame["tick"], frame["bytes"], upright, flipped))


def steer_trailing_camera(browser):
    """--web-control: the page's zoom button, pressed three times, zooms the
    trailing camera in (1.25x a press): its frames come with a narrower view."""
    wait_for("the trailing camera's frame", lambda: browser.run(
        "return window.sandboxView.cameras.trailing"), seconds=100.0)
    before = browser.run("return window.sandboxView.cameras.trailing.fovDeg")
    browser.run("const b = document.querySelector('#steer [data-key=zoom_in]'); "
                "b.click(); b.click(); b.click()")
    after = wait_for("a zoomed trailing frame", lambda: (lambda f: f if f < before * 0.7 else None)(
        browser.run("return window.sandboxView.cameras.trailing.fovDeg")))
    return "zoom pressed 3 times: the trailing camera's view %.1f -> %.1f degrees" % (before, after)


def robot_overlap(browser, sandbox, out):
    """The page held at one state, the wing seen from above and behind it, drawn
    as a mask; `sandbox render` of the same pose and bone values from the same
    camera as a segmentation image. Returns (IoU, tick, robot pixels)."""
    browser.run("window.sandboxControl.hold(true)")
    drawn = browser.run("return window.sandboxView.framesDrawn")
    wait_for("a frame of the held state",
             lambda: browser.run("return window.sandboxView.framesDrawn") > drawn + 1)
    view = browser.run("return window.sandboxView")
    robot = view["robots"]["ELAHA"]
    p, R_WB = robot["p"], matrix_from_quaternion(robot["q"])
    # The camera 17 m up and 6 m back in the wing's frame, looking at it.
    offset = [-6.0, 0.0, 17.0]
    c = [p[i] + sum(R_WB[i][j] * offset[j] for j in range(3)) for i in range(3)]
    forward = [p[i] - c[i] for i in range(3)]
    n = math.sqrt(sum(v * v for v in forward))
    x = [v / n for v in forward]
    left = [-x[1], x[0], 0.0]  # world z cross x
    n = math.sqrt(sum(v * v for v in left))
    y = [v / n for v in left]
    z = [x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0]]
    R_WC = [[x[i], y[i], z[i]] for i in range(3)]
    fov = 60.0
    browser.run("window.sandboxControl.setCamera(%s, %s, %f); window.sandboxControl.mask(true)"
                % (json.dumps(c), json.dumps(quaternion_from_matrix(R_WC)), fov))
    drawn = browser.run("return window.sandboxView.framesDrawn")
    wait_for("a frame from the camera",
             lambda: browser.run("return window.sandboxView.framesDrawn") > drawn + 1)
    shot = browser.screenshot()
    width, height = browser.run("const c = document.getElementById('view'); "
                                "return [c.width, c.height]")
    assert shot.size == (width, height), (shot.size, width, height)
    seg = os.path.join(out, "robot.png")
    subprocess.run([sandbox, "render", "--camera", "fixed", "--at", pose_argument(c, R_WC),
                    "--robot-at", pose_argument(p, R_WB),
                    "--bone-values", ",".join("%.12g" % v for v in robot["bones"]),
                    "--kind", "segmentation", "--width", str(width), "--height", str(height),
                    "--fov", str(fov), "--out", seg], check=True, stdout=subprocess.DEVNULL)
    with open(os.path.join(out, "robot_seg.csv")) as legend:
        ids = {int(row["id"]) for row in csv.DictReader(legend)
               if row["name"].startswith("ELAHA/")}
    theirs = [v in ids for v in Image.open(seg).getdata()]
    ours = [r + g + b > 3 * 128 for r, g, b in shot.getdata()]
    both = sum(1 for a, b in zip(ours, theirs) if a and b)
    either = sum(1 for a, b in zip(ours, theirs) if a or b)
    assert sum(theirs) > 2000, "the wing covers %d pixels of the render" % sum(theirs)
    return both / max(1, either), view["tick"], sum(theirs)


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

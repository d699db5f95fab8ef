"""The live Foxglove server (`--foxglove`) against a client built on Foxglove's
own npm package (@foxglove/ws-protocol, tests/js/foxglove_client.cjs, run with
Debian's nodejs): it subscribes to every channel advertised while a lock-step
run steps, and each FrameTransform and PointCloud it decodes equals the
robot_state_t or scan_face_t of the same time in the run's own LCM recording."""
import json
import os
import pathlib
import queue
import subprocess
import threading
import time

import sandbox
from test_lockstep import inputs
from test_mcap import NODE_PATH, ROOT, check_cloud, check_transform, lcm_events

CLIENT = ROOT / "tests/js/foxglove_client.cjs"


def start_client(url):
    assert (pathlib.Path(NODE_PATH) / "@foxglove/ws-protocol").is_dir(), \
        f"the npm client is not in {NODE_PATH}: run scripts/setup"
    client = subprocess.Popen(["node", str(CLIENT), url], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True,
                              env={**os.environ, "NODE_PATH": NODE_PATH})
    events = queue.Queue()
    threading.Thread(target=lambda: [events.put(json.loads(line)) for line in client.stdout],
                     daemon=True).start()
    return client, events


def wait_for(events, seen, done, seconds=60.0):
    """Takes events into `seen` until done(seen) or the time is up (a 10x slower machine too)."""
    end = time.monotonic() + seconds
    while not done(seen) and time.monotonic() < end:
        try:
            seen.append(events.get(timeout=0.1))
        except queue.Empty:
            pass
    return done(seen)


def test_a_foxglove_client_decodes_the_runs_poses_and_face_scans(tmp_path):
    record = tmp_path / "run.lcmlog"
    steps = list(inputs())
    seen = []
    # A subscription takes effect when the server's thread reads it, which may be
    # after the conversions already queued there: count from the first message of each.
    flowing = lambda s: {e["topic"] for e in s if e["event"] == "message"}
    with sandbox.Lockstep(args=["--foxglove", "0", "--record", str(record)]) as run:
        assert run.foxglove_url.startswith("ws://127.0.0.1:")
        client, events = start_client(run.foxglove_url)
        assert wait_for(events, seen, lambda s: any(e["event"] == "serverInfo" for e in s)), seen
        k = 0
        # Channels are advertised with their first message: step until both flow.
        both = {"ELAHA/STATE/tf", "ELAHA/SCAN_FACE/points"}
        while not both <= flowing(seen) and k < 10:
            utime, position, q, bend = steps[k]
            run.step(poses={"ELAHA": (position, q)}, bones={"ELAHA": bend}, utime=utime)
            k += 1
            wait_for(events, seen, lambda s: both <= flowing(s), seconds=10.0)
        assert both <= flowing(seen), seen
        first = k
        for utime, position, q, bend in steps[first:]:
            run.step(poses={"ELAHA": (position, q)}, bones={"ELAHA": bend}, utime=utime)
        last_utime = steps[-1][0]
        delivered = lambda s: sum(e["event"] == "message" and e["topic"] == "ELAHA/STATE/tf" and
                                  int(e["timestamp"]) == last_utime * 1000 for e in s) > 0
        assert wait_for(events, seen, delivered), "the last tick's pose never came"
    client.terminate()
    client.wait(timeout=30)
    assert not [e for e in seen if e["event"] == "status"], "the server refused a request"

    states, faces = {}, {}
    for channel, _, data in lcm_events(record):
        if channel in ("ELAHA/STATE", "ELAHA/SCAN_FACE"):
            message = sandbox.decode(data)
            (states if channel == "ELAHA/STATE" else faces)[message.utime] = message
    transforms = clouds = 0
    for event in seen:
        if event["event"] != "message" or event["schemaName"] not in (
                "foxglove.FrameTransform", "foxglove.PointCloud"):
            continue
        stamp = event["message"]["timestamp"]
        utime = stamp["sec"] * 10**6 + stamp["nsec"] // 1000
        if event["schemaName"] == "foxglove.FrameTransform":
            check_transform(event["message"], states[utime])
            transforms += 1
        elif event["schemaName"] == "foxglove.PointCloud":
            check_cloud(event["message"], faces[utime])
            clouds += 1
    # Every tick after both flowed, at least.
    assert transforms >= len(steps) - first and clouds >= len(steps) - first, (transforms, clouds)


def handshake(port, protocol="foxglove.websocket.v1", origin=None, host="127.0.0.1", path="/"):
    """The HTTP status line the server answers a WebSocket handshake with."""
    import socket
    lines = [f"GET {path} HTTP/1.1", f"Host: {host}:{port}", "Upgrade: websocket",
             "Connection: Upgrade", "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==",
             "Sec-WebSocket-Version: 13"]
    if protocol:
        lines.append(f"Sec-WebSocket-Protocol: {protocol}")
    if origin:
        lines.append(f"Origin: {origin}")
    with socket.create_connection(("127.0.0.1", port), timeout=30) as s:
        s.sendall(("\r\n".join(lines) + "\r\n\r\n").encode())
        return s.recv(4096).decode(errors="replace").split("\r\n")[0]


def test_the_server_keeps_the_browser_views_rules(tmp_path):
    with sandbox.Lockstep(args=["--foxglove", "0"]) as run:
        port = int(run.foxglove_url.rsplit(":", 1)[1].strip("/"))
        assert " 101 " in handshake(port)
        assert " 101 " in handshake(port, origin=f"http://127.0.0.1:{port}")  # its own address
        assert " 400 " in handshake(port, protocol=None)          # not the Foxglove protocol
        assert " 400 " in handshake(port, path="/stream")
        assert " 403 " in handshake(port, origin="https://evil.example")
        assert " 403 " in handshake(port, host="rebound.example")  # DNS rebinding

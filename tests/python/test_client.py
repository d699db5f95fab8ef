"""sandbox.Client against a running sandbox over LCM UDP multicast, inside a
private network namespace (scripts/netns-run; the test re-runs itself there).

examples/python/controller_bench.py drives `sandbox run --lockstep`: every
pose it publishes must come back as that tick's STATE (to 1e-9 m), the
altimeter's hits must lie on the sample terrain's analytic surface, and the
controller must hold its height.
"""
import json
import math
import os
import pathlib
import subprocess
import sys

import pytest

import sandbox
from sample_terrain import terrain_height

ROOT = pathlib.Path(__file__).resolve().parents[2]
SANDBOX = os.environ.get("SANDBOX", "sandbox")
URL = "udpm://239.255.76.67:7667?ttl=0"
STEPS = 300


def in_namespace():
    return os.environ.get("SANDBOX_IN_NETNS") == "1"


def test_in_a_private_network_namespace():
    if in_namespace():
        return
    result = subprocess.run([str(ROOT / "scripts/netns-run"), sys.executable, "-m", "pytest", "-q",
                             "-p", "no:cacheprovider", __file__], capture_output=True, text=True,
                            timeout=600)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "5 passed" in result.stdout, result.stdout


@pytest.fixture(scope="module")
def bench(tmp_path_factory):
    if not in_namespace():
        pytest.skip("runs inside scripts/netns-run (test_in_a_private_network_namespace)")
    folder = tmp_path_factory.mktemp("client")
    run = subprocess.Popen([SANDBOX, "run", "--lockstep", "--lcm-url", URL, "--realtime", "off",
                            "--ticks", str(STEPS), "--record", str(folder / "run.lcmlog")],
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        result = subprocess.run([sys.executable, str(ROOT / "examples/python/controller_bench.py"),
                                 "--url", URL, "--steps", str(STEPS)], capture_output=True,
                                text=True, timeout=300)
        assert result.returncode == 0, result.stderr
        summary = run.communicate(timeout=60)[0]
    finally:
        run.kill()
    return json.loads(result.stdout), summary, sandbox.read_log(folder / "run.lcmlog")


def test_every_pose_came_back_as_its_tick(bench):
    flight, summary, record = bench
    assert flight["steps"] == STEPS and f"{STEPS} ticks" in summary
    states = record["ELAHA/STATE"]
    assert len(states) == STEPS
    positions = states.array("position")
    for row, position in zip(flight["rows"], positions):
        assert abs(row["x"] - position[0]) < 1e-9 and abs(row["z"] - position[2]) < 1e-9


def test_the_altimeter_hits_the_terrain(bench):
    flight, _, _ = bench
    hits = [row["ground"] for row in flight["rows"] if row["ground"]]
    assert len(hits) >= STEPS // 2 - 1
    for x, y, z in hits:
        assert abs(z - terrain_height(x, y)) < 0.1


def test_the_controller_holds_its_height(bench):
    flight, _, _ = bench
    assert flight["max_error_m"] < 3.0 and flight["mean_error_m"] < 1.5


def test_client_arguments_are_checked():
    client = sandbox.Client("memq://")
    with pytest.raises(ValueError, match="position"):
        client.publish_pose("ELAHA", (0, 0))
    with pytest.raises(ValueError, match="orientation"):
        client.publish_pose("ELAHA", (0, 0, 0), (2, 0, 0, 0))
    with pytest.raises(ValueError, match="bones"):
        client.publish_bones("ELAHA", [1.0, math.inf])
    with pytest.raises(ValueError, match="actors"):
        client.publish_actors("ELAHA", [1, 2])
    client.publish_joints("ELAHA", {"R1": 0.1})
    [(channel, message)] = client.receive(timeout=1.0)  # memq:// hears its own
    assert channel == "ELAHA/JOINTS" and message.names == ["R1"] and message.values[0] == 0.1

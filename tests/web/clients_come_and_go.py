#!/usr/bin/python3
"""The browser view's server under clients that come and go, and a client that
never reads, with no browser (Python sockets and bench/web_clients).

1. `sandbox run --web 0` over memq://: eight clients connect, read for a
   second and leave, twenty times; the sandbox's resident memory after the
   last time is within 5% of what it was after the first.
2. A lock-step replay of a 5 min flight with --record and --web, without a
   client and with a client
   that opens the stream and never reads: the recorded outputs are identical
   (log_diff; all but STATUS, whose loop rate is measured), the ticks the
   same; the summary counts the states skipped for
   the slow client.

usage: clients_come_and_go.py SANDBOX FLY_WING WEB_CLIENTS LOG_DIFF
"""
import base64
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from browser_view import served  # noqa: E402


def rss_kib(pid):
    with open("/proc/%d/status" % pid) as status:
        for line in status:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    raise AssertionError("no VmRSS for %d" % pid)


def start_serving(args):
    process = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    return process, served(process, r"browser view at http://([^/\s]+)/").group(1)


def stop(process):
    process.send_signal(signal.SIGINT)
    rest, _ = process.communicate(timeout=120)
    return rest


def memory(sandbox, web_clients):
    run, host = start_serving([sandbox, "run", "--web", "0", "--lcm-url", "memq://",
                               "--duration", "600"])
    try:
        def cycle():
            subprocess.run([web_clients, "ws://%s/stream" % host, "8", "1"], check=True,
                           stdout=subprocess.DEVNULL)
        cycle()
        cycle()
        first = rss_kib(run.pid)
        for _ in range(20):
            cycle()
        time.sleep(0.5)
        last = rss_kib(run.pid)
    finally:
        rest = stop(run)
    clients = int(re.search(r"browser view: (\d+) clients \((\d+) at the end\)", rest).group(1))
    assert clients == 22 * 8, rest
    change = (last - first) / first
    print("clients come and go: 8 clients x 20 times, resident memory %d -> %d KiB (%+.1f%%)"
          % (first, last, 100 * change))
    assert abs(change) <= 0.05, (first, last)


def never_reads(host):
    """A WebSocket client that sends its handshake and then never reads
    (connecting as soon as the server listens)."""
    address, port = host.rsplit(":", 1)
    end = time.monotonic() + 60
    while True:
        try:
            s = socket.create_connection((address, int(port)))
            break
        except ConnectionRefusedError:
            if time.monotonic() > end:
                raise
            time.sleep(0.01)
    s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
    key = base64.b64encode(os.urandom(16)).decode()
    s.sendall(("GET /stream HTTP/1.1\r\nHost: %s\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
               "Sec-WebSocket-Key: %s\r\nSec-WebSocket-Version: 13\r\n\r\n" % (host, key)).encode())
    return s


def lockstep(sandbox, fly_wing, log_diff, work):
    log = os.path.join(work, "flight.lcmlog")
    subprocess.run([fly_wing, "--write-log", log, "--duration", "300", "--rate", "100"],
                   check=True, stdout=subprocess.DEVNULL)
    alone = os.path.join(work, "alone.lcmlog")
    # Served too, but nobody comes: the two runs differ by the slow client alone.
    run = subprocess.run([sandbox, "run", "--replay", log, "--record", alone, "--web", "0"],
                         check=True,
                         stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    ticks_alone = re.search(r"sandbox run: (\d+) ticks", run.stdout).group(1)
    watched = os.path.join(work, "watched.lcmlog")
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    replay = subprocess.Popen([sandbox, "run", "--replay", log, "--record", watched, "--web",
                               str(port)], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                              text=True)
    client = never_reads("127.0.0.1:%d" % port)
    rest, _ = replay.communicate(timeout=900)
    client.close()
    assert replay.returncode == 0, rest
    ticks_watched = re.search(r"sandbox run: (\d+) ticks", rest).group(1)
    assert ticks_alone == ticks_watched == "30000", (ticks_alone, ticks_watched)
    # Every output but STATUS, which carries the measured loop rate.
    same = subprocess.run([log_diff, alone, watched, "ELAHA/(STATE|SCAN_FACE|RANGE|WORLD)"],
                          stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, text=True)
    assert same.returncode == 0, same.stdout
    counts = re.search(r"browser view: .*?(\d+) states sent, (\d+) skipped for slow clients", rest)
    assert counts and int(counts.group(2)) > 0, rest
    durations = [re.search(r"tick duration: p50 ([0-9.]+) ms, p99 ([0-9.]+) ms", text).groups()
                 for text in (run.stdout, rest)]
    print("a client that never reads: %s ticks replayed and recorded as without it (log_diff: "
          "identical); %s states sent, %s skipped for the slow client; tick duration p50/p99 "
          "%s/%s ms without it, %s/%s ms with it"
          % (ticks_watched, counts.group(1), counts.group(2), *durations[0], *durations[1]))


def main():
    sandbox, fly_wing, web_clients, log_diff = sys.argv[1:5]
    work = tempfile.mkdtemp(prefix="sandbox-clients-")
    try:
        memory(sandbox, web_clients)
        lockstep(sandbox, fly_wing, log_diff, work)
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()

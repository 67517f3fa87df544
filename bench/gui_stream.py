#!/usr/bin/env python3
"""Streaming figures of a running GUI (saccade gui / saccade demo --gui), as a script client.

    python3 bench/gui_stream.py [--url http://127.0.0.1:8080/] [--seconds 20] [--slow-clients 0]

Connects to the WebSocket (docs/gui-protocol.md) and measures, over --seconds:
  - frames per second received per camera, states per second, the loop's steps per second;
  - the round trip of `ping` (median, p95) and the latency of a `joints` command until a state
    shows the new target (median, p95), alternating the pan target between two values, each
    command sent as soon as a state shows the one before (so most land while the head turns);
  - from rest: --commands more, each sent a random 0.1-0.35 s after a state says the head
    arrived at the one before (at a random phase of the loop's step), timed until a state shows the new target and until a state shows the pan
    moving towards it (the step the command lands in, or the next);
  - with --frame-ms MS: the client takes MS to finish with each frame (as a browser that
    decodes and draws slower than the server renders); with --window W it asks for a frame
    window of W (`frame_window`) and acknowledges each frame when done (`frame_ack`), which
    bounds how many frames (and the states and replies behind them) wait for it;
  - with --slow-clients N (before the commands, which switch perception off): N more clients
    connect and never read; the loop's steps per second with them is reported next to the
    figure without them, and what the server held and skipped for them (/api/status).
Python's standard library only. Prints a table; --json prints JSON.
"""

import argparse
import base64
import json
import os
import random
import socket
import statistics
import struct
import sys
import time
import urllib.parse
import urllib.request


class Ws:
    """A minimal WebSocket client (RFC 6455): text and binary messages, no extensions."""

    def __init__(self, host, port, path, read=True):
        self.sock = socket.create_connection((host, port), timeout=30)
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        if not read:  # a slow client: a tiny receive buffer it never drains
            self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        key = base64.b64encode(os.urandom(16)).decode()
        self.sock.sendall(
            (f"GET {path} HTTP/1.1\r\nHost: {host}:{port}\r\nUpgrade: websocket\r\n"
             f"Connection: Upgrade\r\nSec-WebSocket-Key: {key}\r\n"
             "Sec-WebSocket-Version: 13\r\n\r\n").encode())
        head = b""
        while b"\r\n\r\n" not in head:
            chunk = self.sock.recv(4096)
            if not chunk:
                raise SystemExit("gui_stream: the server closed the connection during the handshake")
            head += chunk
        status = head.split(b"\r\n", 1)[0].decode()
        if " 101 " not in status:
            raise SystemExit(f"gui_stream: WebSocket refused: {status}")
        self.rest = head.split(b"\r\n\r\n", 1)[1]

    def _exact(self, n):
        while len(self.rest) < n:
            chunk = self.sock.recv(1 << 20)
            if not chunk:
                raise EOFError
            self.rest += chunk
        data, self.rest = self.rest[:n], self.rest[n:]
        return data

    def read(self):
        """(opcode, payload) of the next whole message (1 text, 2 binary), fragments joined."""
        op, payload = None, b""
        while True:
            h = self._exact(2)
            fin, frame_op, n = h[0] & 0x80, h[0] & 15, h[1] & 127
            if n == 126:
                n = struct.unpack(">H", self._exact(2))[0]
            elif n == 127:
                n = struct.unpack(">Q", self._exact(8))[0]
            data = self._exact(n)
            if frame_op >= 8:  # control frames (ping, pong, close) between fragments
                if frame_op == 8:
                    raise EOFError
                continue
            op = frame_op if frame_op != 0 else op
            payload += data
            if fin:
                return op, payload

    def send(self, obj):
        data = json.dumps(obj).encode()
        mask = os.urandom(4)
        n = len(data)
        head = bytes([0x81]) + (bytes([0x80 | n]) if n < 126 else bytes([0x80 | 126]) + struct.pack(">H", n))
        self.sock.sendall(head + mask + bytes(b ^ mask[i % 4] for i, b in enumerate(data)))


def percentile(values, q):
    values = sorted(values)
    return values[min(len(values) - 1, int(q * (len(values) - 1) + 0.5))] if values else float("nan")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--url", default="http://127.0.0.1:8080/", help="the address saccade printed")
    parser.add_argument("--seconds", type=float, default=20.0, help="how long to count frames")
    parser.add_argument("--commands", type=int, default=10, help="joints commands to time")
    parser.add_argument("--slow-clients", type=int, default=0, help="clients that never read")
    parser.add_argument("--frame-ms", type=float, default=0.0,
                        help="milliseconds this client spends on each frame (a slow page)")
    parser.add_argument("--window", type=int, default=0,
                        help="frames sent and not acknowledged at most (frame_window; 0: none)")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    url = urllib.parse.urlparse(args.url)
    token = urllib.parse.parse_qs(url.query).get("token", [None])[0]
    path = "/ws" + (f"?token={token}" if token else "")
    api = f"http://{url.hostname}:{url.port}/api/status" + (f"?token={token}" if token else "")

    ws = Ws(url.hostname, url.port, path)
    next_id = [0]

    def command(obj):
        next_id[0] += 1
        obj["id"] = next_id[0]
        ws.send(obj)
        return next_id[0]

    frames, states, last_state = {}, 0, None
    frames_done = [0]
    if args.window:
        command({"type": "frame_window", "frames": args.window})
    ping_ms, joints_ms, rest_ms, motion_ms = [], [], [], []
    pending_ping, pending_joint = {}, None  # id -> sent; (target, sent)
    # From rest: [target, sent, pan when sent, target shown, motion shown]
    from_rest = None

    def pump(until):
        nonlocal states, last_state, pending_joint, from_rest
        while time.monotonic() < until:
            op, data = ws.read()
            now = time.monotonic()
            if op == 2:
                n = struct.unpack("<I", data[:4])[0]
                camera = json.loads(data[4:4 + n])["camera"]
                frames[camera] = frames.get(camera, 0) + 1
                if args.frame_ms:
                    time.sleep(args.frame_ms / 1e3)
                frames_done[0] += 1
                if args.window:
                    command({"type": "frame_ack", "frames": frames_done[0]})
            elif op == 1:
                m = json.loads(data)
                if m["type"] == "state":
                    states += 1
                    last_state = m
                    if pending_joint and m.get("joints") and abs(m["joints"]["targets"]["pan"] - pending_joint[0]) < 1e-9:
                        joints_ms.append(1e3 * (now - pending_joint[1]))
                        pending_joint = None
                    if from_rest and m.get("joints"):
                        j = m["joints"]
                        target, sent, pan0, shown, moving = from_rest
                        if not shown and abs(j["targets"]["pan"] - target) < 1e-9:
                            rest_ms.append(1e3 * (now - sent))
                            from_rest[3] = shown = True
                        moved = j["positions"]["pan"] - pan0
                        if not moving and moved * (target - pan0) > 0 and abs(moved) > 1e-4:
                            motion_ms.append(1e3 * (now - sent))
                            from_rest[4] = moving = True
                        if shown and moving and j["arrived"]:
                            from_rest = None
                elif m["type"] == "reply" and m["id"] in pending_ping:
                    ping_ms.append(1e3 * (now - pending_ping.pop(m["id"])))
                elif m["type"] == "error":
                    print(f"gui_stream: error reply: {m['error']}", file=sys.stderr)

    # Frames and states as they come.
    pump(time.monotonic() + 2.0)  # let the first frames arrive
    frames.clear()
    states = 0
    t0 = time.monotonic()
    steps0 = last_state["step"] if last_state else 0
    pump(t0 + args.seconds)
    elapsed = time.monotonic() - t0
    steps_per_s = ((last_state["step"] if last_state else 0) - steps0) / elapsed
    states_per_s = states / elapsed
    frames_per_s = {c: n / elapsed for c, n in sorted(frames.items())}

    slow = None
    if args.slow_clients > 0:
        laggards = [Ws(url.hostname, url.port, path, read=False) for _ in range(args.slow_clients)]
        step_a = last_state["step"]
        t1 = time.monotonic()
        pump(t1 + args.seconds)
        slow_steps_per_s = (last_state["step"] - step_a) / (time.monotonic() - t1)
        status = json.load(urllib.request.urlopen(api))
        ports = {str(l.sock.getsockname()[1]) for l in laggards}
        held = [c for c in status["clients"] if c["peer"].rsplit(":", 1)[-1] in ports]
        slow = {"clients": args.slow_clients, "steps_per_s": slow_steps_per_s,
                "queued_bytes_max": max((c["queued_bytes"] for c in held), default=0),
                "frames_sent_max": max((c["frames_sent"] for c in held), default=0),
                "frames_skipped_total": sum(c["frames_skipped"] for c in held)}
        del laggards

    # Pings, one at a time.
    for _ in range(20):
        pending_ping[command({"type": "ping"})] = time.monotonic()
        deadline = time.monotonic() + 10
        while pending_ping and time.monotonic() < deadline:
            pump(time.monotonic() + 0.01)
    # Joint commands until a state shows them (the perception loop is switched off by them).
    for k in range(args.commands):
        target = 0.1 if k % 2 == 0 else -0.1
        pending_joint = (target, time.monotonic())
        command({"type": "joints", "positions": {"pan": target}})
        deadline = time.monotonic() + 30
        while pending_joint and time.monotonic() < deadline:
            pump(time.monotonic() + 0.01)
    # From rest: once the head arrived, a random pause (the loop's phase), then the command.
    rng = random.Random(1)
    for k in range(args.commands if joints_ms else 0):
        deadline = time.monotonic() + 30
        while not (last_state["joints"]["arrived"]) and time.monotonic() < deadline:
            pump(time.monotonic() + 0.01)
        pump(time.monotonic() + rng.uniform(0.1, 0.3))
        time.sleep(rng.uniform(0.0, 0.05))  # not just after a state: a random phase of the step
        target = 0.1 if k % 2 == 0 else -0.1
        from_rest = [target, time.monotonic(), last_state["joints"]["positions"]["pan"], False, False]
        command({"type": "joints", "positions": {"pan": target}})
        while from_rest and time.monotonic() < deadline:
            pump(time.monotonic() + 0.01)

    result = {
        "seconds": elapsed, "steps_per_s": steps_per_s, "states_per_s": states_per_s,
        "frames_per_s": frames_per_s,
        "ping_ms": {"median": statistics.median(ping_ms), "p95": percentile(ping_ms, 0.95)},
        "joints_to_state_ms": {"median": statistics.median(joints_ms) if joints_ms else None,
                               "p95": percentile(joints_ms, 0.95), "n": len(joints_ms)},
        "from_rest": {
            "joints_to_state_ms": {"median": statistics.median(rest_ms) if rest_ms else None,
                                   "p95": percentile(rest_ms, 0.95), "n": len(rest_ms)},
            "joints_to_motion_ms": {"median": statistics.median(motion_ms) if motion_ms else None,
                                    "p95": percentile(motion_ms, 0.95), "n": len(motion_ms)}},
        "slow": slow, "frame_ms": args.frame_ms, "window": args.window,
    }
    if args.json:
        print(json.dumps(result, indent=2))
        return
    print(f"over {elapsed:.1f} s: {steps_per_s:.2f} steps/s, {states_per_s:.2f} states/s, frames/s "
          + ", ".join(f"{c} {f:.2f}" for c, f in frames_per_s.items()))
    print(f"ping round trip: median {result['ping_ms']['median']:.2f} ms, p95 {result['ping_ms']['p95']:.2f} ms")
    if joints_ms:
        print(f"joints command to a state with the new target ({len(joints_ms)}): median "
              f"{statistics.median(joints_ms):.1f} ms, p95 {percentile(joints_ms, 0.95):.1f} ms")
    if rest_ms and motion_ms:
        print(f"from rest ({len(rest_ms)}): to a state with the new target median "
              f"{statistics.median(rest_ms):.1f} ms, p95 {percentile(rest_ms, 0.95):.1f} ms; to a "
              f"state with the pan moving towards it median {statistics.median(motion_ms):.1f} ms, "
              f"p95 {percentile(motion_ms, 0.95):.1f} ms")
    if slow:
        print(f"with {slow['clients']} clients that never read: {slow['steps_per_s']:.2f} steps/s "
              f"(without: {steps_per_s:.2f}); held for each at most {slow['queued_bytes_max'] / 1e6:.2f} MB, "
              f"{slow['frames_skipped_total']} frames skipped for them (each was sent at most "
              f"{slow['frames_sent_max']}, into its socket buffers)")


if __name__ == "__main__":
    main()

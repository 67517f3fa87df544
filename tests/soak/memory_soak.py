#!/usr/bin/env python3
"""Long runs with resident memory sampled (issue 18, item 3). Not part of the default test
run. Standard library only.

  python3 tests/soak/memory_soak.py demo [--steps 100000] [--binary build/bin/saccade]
  python3 tests/soak/memory_soak.py gui  [--seconds 3600] [--clients 5]

demo: `saccade demo` for --steps steps of the loop (0.04 s each) with the soak configuration,
  pipelines/soak.yaml on scenes/soak.yaml (--pipeline another): the demo's loop with every
  component on (the renderer's distortion, motion blur and noise; undistortion, median and
  sharpening besides the detectors, trackers, triangulation, attention and fixation) on 352 x 264
  eye images, whose attention dwells on a face until its track is lost (fixation_time_s: 1e6), so
  that the run does not end early ("every face fixated") and the loop keeps detecting, tracking
  and pursuing the sliding portraits to the last step. The report (--json) must say that every
  step ran.
gui: `saccade gui --port 0 --no-token` on the same configuration, at --speed (1: real time), with
  --clients WebSocket clients of the browser
  protocol (docs/gui-protocol.md), written here on sockets: each reads every state and frame
  and sends a command a second (ping, joints, effects, fixate, in turn) and must get a reply
  to each; the run lasts --seconds.

The program's resident set (VmRSS) is sampled every --every seconds (and written as it is
taken to --log FILE, when given). After the warm-up
(--warmup, a fraction of the run, 0.2 by default), the largest sample may exceed the first one
by at most --tolerance (2 %): memory must stay flat. With --asan the binary is expected to be
built with AddressSanitizer: its leak report at exit (LeakSanitizer) must be empty, and RSS
is reported but not judged (ASan's quarantine grows by design). Prints the samples as a table
every tenth of the run and a last line with the verdict; exits 1 on a failure.
"""
import argparse
import base64
import json
import os
import re
import signal
import socket
import struct
import subprocess
import sys
import tempfile
import threading
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def rss_kib(pid):
    """VmRSS of the process in KiB, None once it is gone."""
    try:
        with open(f'/proc/{pid}/status') as f:
            for line in f:
                if line.startswith('VmRSS:'):
                    return int(line.split()[1])
    except OSError:
        return None
    return None


class Sampler(threading.Thread):
    """Samples a process's RSS every `every` seconds until it exits or stop() is called."""

    def __init__(self, pid, every, log=None):
        super().__init__(daemon=True)
        self.pid, self.every = pid, every
        self.samples = []  # (seconds since start, KiB)
        self._halt = threading.Event()
        self.start_time = time.monotonic()
        self._log = None
        if log:
            self._log = open(log, 'w')
            self._log.write('seconds,rss_kib\n')
            self._log.flush()

    def run(self):
        while not self._halt.is_set():
            kib = rss_kib(self.pid)
            if kib is None:
                return
            t = time.monotonic() - self.start_time
            self.samples.append((t, kib))
            if self._log:  # as it is taken: a run cut short keeps its record
                self._log.write(f'{t:.1f},{kib}\n')
                self._log.flush()
            self._halt.wait(self.every)

    def stop(self):
        self._halt.set()
        self.join()


def judge(samples, warmup, tolerance, duration):
    """(ok, text): the largest sample after the warm-up against the first one after it."""
    after = [s for s in samples if s[0] >= warmup * duration]
    if len(after) < 2:
        return False, f'only {len(after)} samples after the warm-up: run longer'
    base = after[0][1]
    peak = max(kib for _, kib in after)
    last = after[-1][1]
    growth = (peak - base) / base
    text = (f'RSS after the warm-up ({after[0][0]:.0f} s): {base / 1024:.1f} MiB; largest '
            f'{peak / 1024:.1f} MiB (+{100 * growth:.2f} %), last {last / 1024:.1f} MiB; '
            f'{len(samples)} samples over {samples[-1][0]:.0f} s')
    return growth <= tolerance, text


def print_table(samples, rows=10):
    if not samples:
        return
    step = max(1, len(samples) // rows)
    print('   time s    RSS MiB')
    for t, kib in samples[::step] + ([samples[-1]] if (len(samples) - 1) % step else []):
        print(f'{t:9.0f} {kib / 1024:10.1f}')


def leak_report(stderr_text):
    """The LeakSanitizer summary lines, empty when none."""
    return [line for line in stderr_text.splitlines()
            if 'LeakSanitizer' in line or line.startswith('SUMMARY: AddressSanitizer')]


# ---- demo ---------------------------------------------------------------------------------

def run_demo(args):
    dt = 0.04
    with tempfile.TemporaryDirectory(prefix='saccade-soak-') as tmp:
        command = [args.binary, 'demo', '--pipeline', args.pipeline,
                   '--duration', repr(args.steps * dt), '--json']
        print('soak:', ' '.join(command), flush=True)
        out_path, err_path = os.path.join(tmp, 'out.json'), os.path.join(tmp, 'err.txt')
        with open(out_path, 'w') as out, open(err_path, 'w') as err:
            started = time.monotonic()
            process = subprocess.Popen(command, stdout=out, stderr=err, cwd=ROOT)
            sampler = Sampler(process.pid, args.every, args.log)
            sampler.start()
            status = process.wait()
            wall = time.monotonic() - started
            sampler.stop()
        with open(out_path) as f:
            out_text = f.read()
        with open(err_path) as f:
            err_text = f.read()
    problems = []
    if status != 0:
        problems.append(f'exit status {status}: {err_text[-2000:]}')
    steps = None
    try:
        report = json.loads(out_text)
        steps = report.get('steps', report.get('summary', {}).get('steps'))
    except ValueError:
        problems.append('the report is not JSON: ' + out_text[-500:])
    if steps is not None and steps != args.steps:
        problems.append(f'{steps} steps ran, not {args.steps}')
    print_table(sampler.samples)
    print(f'demo: {steps} steps in {wall:.0f} s ({(steps or 0) / wall:.2f} steps/s)')
    return finish(args, sampler.samples, wall, problems, err_text)


def finish(args, samples, wall, problems, err_text):
    if args.asan:
        leaks = leak_report(err_text)
        if leaks:
            problems.append('leaks:\n  ' + '\n  '.join(leaks[:10]))
        print(f'ASan/LSan: {"no report" if not leaks else f"{len(leaks)} report lines"}')
        if samples:
            print(f'RSS (not judged under ASan): {samples[0][1] / 1024:.1f} MiB first, '
                  f'{max(k for _, k in samples) / 1024:.1f} MiB largest')
    else:
        ok, text = judge(samples, args.warmup, args.tolerance, wall) if samples else (
            False, 'no RSS sample')
        print(text)
        if not ok:
            problems.append(f'memory grew more than {100 * args.tolerance:.0f} % after the '
                            f'warm-up: {text}')
    for p in problems:
        print('FAILED:', p)
    print('soak: ' + ('passed' if not problems else 'FAILED'))
    return 1 if problems else 0


# ---- gui ----------------------------------------------------------------------------------

class WebSocket:
    """A client WebSocket (RFC 6455) on a plain socket: text and binary messages, masked."""

    def __init__(self, port, path='/ws'):
        self.sock = socket.create_connection(('127.0.0.1', port), timeout=30)
        key = base64.b64encode(os.urandom(16)).decode()
        self.sock.sendall((f'GET {path} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n'
                           f'Upgrade: websocket\r\nConnection: Upgrade\r\n'
                           f'Sec-WebSocket-Key: {key}\r\nSec-WebSocket-Version: 13\r\n\r\n')
                          .encode())
        head = b''
        while b'\r\n\r\n' not in head:
            chunk = self.sock.recv(4096)
            if not chunk:
                raise ConnectionError('closed during the handshake')
            head += chunk
        status = head.split(b'\r\n', 1)[0]
        if b' 101 ' not in status:
            raise ConnectionError(f'handshake refused: {status!r}')
        self.buffer = head.split(b'\r\n\r\n', 1)[1]
        self.lock = threading.Lock()

    def _read(self, n):
        while len(self.buffer) < n:
            chunk = self.sock.recv(65536)
            if not chunk:
                raise ConnectionError('closed')
            self.buffer += chunk
        data, self.buffer = self.buffer[:n], self.buffer[n:]
        return data

    def receive(self):
        """(opcode, payload) of the next whole message."""
        payload, opcode = b'', None
        while True:
            b0, b1 = self._read(2)
            length = b1 & 0x7f
            if length == 126:
                (length,) = struct.unpack('>H', self._read(2))
            elif length == 127:
                (length,) = struct.unpack('>Q', self._read(8))
            data = self._read(length)
            if b0 & 0x0f:
                opcode = b0 & 0x0f
            if opcode == 9:  # ping: answer, keep reading
                self._send(10, data)
                continue
            payload += data
            if b0 & 0x80:
                return opcode, payload

    def _send(self, opcode, data):
        mask = os.urandom(4)
        n = len(data)
        head = bytes([0x80 | opcode])
        if n < 126:
            head += bytes([0x80 | n])
        elif n < 65536:
            head += bytes([0x80 | 126]) + struct.pack('>H', n)
        else:
            head += bytes([0x80 | 127]) + struct.pack('>Q', n)
        masked = bytes(b ^ mask[i % 4] for i, b in enumerate(data))
        with self.lock:
            self.sock.sendall(head + mask + masked)

    def send_text(self, text):
        self._send(1, text.encode())

    def close(self):
        try:
            self._send(8, struct.pack('>H', 1000))
        except OSError:
            pass
        self.sock.close()


class Client(threading.Thread):
    """Reads everything; sends a command a second and counts the replies and errors."""

    COMMANDS = [
        {'type': 'ping'},
        {'type': 'joints', 'positions': {'pan': 0.2, 'tilt': -0.1}},
        {'type': 'effects', 'noise': True, 'motion_blur': False},
        {'type': 'fixate', 'p_W': [2.0, 0.3, 1.2]},
        {'type': 'joints', 'positions': {'pan': -0.2, 'vergence': 0.05}},
        {'type': 'effects', 'noise': False, 'motion_blur': True},
    ]

    def __init__(self, index, port, stop):
        super().__init__(daemon=True)
        self.index, self.port, self.stop_event = index, port, stop
        self.counts = {'state': 0, 'frame': 0, 'reply': 0, 'error': 0, 'other': 0}
        self.sent = 0
        self.failure = None
        self.errors = []

    def run(self):
        try:
            ws = WebSocket(self.port)
        except OSError as e:
            self.failure = f'client {self.index}: {e}'
            return
        reader = threading.Thread(target=self.read, args=(ws,), daemon=True)
        reader.start()
        next_id = 1
        while not self.stop_event.wait(1.0) and self.failure is None:
            command = dict(self.COMMANDS[(next_id + self.index) % len(self.COMMANDS)], id=next_id)
            try:
                ws.send_text(json.dumps(command))
            except OSError as e:
                self.failure = f'client {self.index}: send: {e}'
                break
            self.sent += 1
            next_id += 1
        ws.close()
        reader.join(timeout=5)

    def read(self, ws):
        try:
            while True:
                opcode, payload = ws.receive()
                if opcode == 8:
                    return
                if opcode == 2:
                    self.counts['frame'] += 1
                    continue
                message = json.loads(payload)
                kind = message.get('type')
                self.counts[kind if kind in self.counts else 'other'] += 1
                if kind == 'error':
                    self.errors.append(message.get('error'))
        except (OSError, ConnectionError, ValueError) as e:
            if not self.stop_event.is_set():
                self.failure = f'client {self.index}: read: {e}'


def run_gui(args):
    command = [args.binary, 'gui', '--port', '0', '--no-token', '--pipeline', args.pipeline,
               '--speed', repr(args.speed)]
    print('soak:', ' '.join(command), flush=True)
    with tempfile.TemporaryDirectory(prefix='saccade-soak-') as tmp:
        err_path = os.path.join(tmp, 'err.txt')
        with open(err_path, 'w') as err:
            process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=err, cwd=ROOT,
                                       text=True)
            port = None
            deadline = time.monotonic() + 120
            while port is None and time.monotonic() < deadline:
                line = process.stdout.readline()
                if not line:
                    break
                match = re.search(r'gui: serving http://[^:]+:(\d+)/', line)
                if match:
                    port = int(match.group(1))
            if port is None:
                process.kill()
                process.wait()
                with open(err_path) as f:
                    print('FAILED: no address printed:', f.read()[-2000:])
                return 1
            threading.Thread(target=lambda: process.stdout.read(), daemon=True).start()
            started = time.monotonic()
            sampler = Sampler(process.pid, args.every, args.log)
            sampler.start()
            stop = threading.Event()
            clients = [Client(i, port, stop) for i in range(args.clients)]
            for c in clients:
                c.start()
            while time.monotonic() - started < args.seconds and process.poll() is None:
                time.sleep(1)
            stop.set()
            for c in clients:
                c.join(timeout=10)
            wall = time.monotonic() - started
            alive = process.poll() is None
            sampler.stop()
            process.send_signal(signal.SIGINT)
            try:
                status = process.wait(timeout=120)
            except subprocess.TimeoutExpired:
                process.kill()
                status = process.wait()
        with open(err_path) as f:
            err_text = f.read()
    problems = []
    if not alive:
        problems.append(f'the server exited during the run: {err_text[-2000:]}')
    if status != 0:
        problems.append(f'exit status {status} after SIGINT: {err_text[-2000:]}')
    for c in clients:
        print(f'client {c.index}: {c.sent} commands, {c.counts["reply"]} replies, '
              f'{c.counts["error"]} errors, {c.counts["state"]} states, {c.counts["frame"]} '
              f'frames')
        if c.failure:
            problems.append(c.failure)
        # The last command may be in flight when the client stops.
        if c.counts['reply'] + c.counts['error'] < c.sent - 1:
            problems.append(f'client {c.index}: {c.sent} commands but '
                            f'{c.counts["reply"] + c.counts["error"]} answers')
        if c.counts['state'] == 0:
            problems.append(f'client {c.index}: no state received')
        if c.errors:
            print(f'  errors: {sorted(set(c.errors))[:3]}')
    print_table(sampler.samples)
    return finish(args, sampler.samples, wall, problems, err_text)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('what', choices=['demo', 'gui'])
    parser.add_argument('--binary', default=os.path.join(ROOT, 'build', 'bin', 'saccade'))
    parser.add_argument('--pipeline', default=os.path.join(ROOT, 'pipelines', 'soak.yaml'),
                        help='the pipeline (pipelines/soak.yaml, whose scene is scenes/soak.yaml)')
    parser.add_argument('--steps', type=int, default=100000, help='demo: steps (100000)')
    parser.add_argument('--speed', type=float, default=1.0,
                        help='gui: simulated seconds per wall second, at most (1: real time)')
    parser.add_argument('--seconds', type=float, default=3600, help='gui: wall seconds (3600)')
    parser.add_argument('--clients', type=int, default=5, help='gui: WebSocket clients (5)')
    parser.add_argument('--every', type=float, default=2.0, help='RSS sample period, s (2)')
    parser.add_argument('--log', help='also write each RSS sample to this CSV as it is taken '
                        '(seconds,rss_kib), so that a run cut short keeps its record')
    parser.add_argument('--warmup', type=float, default=0.2,
                        help='fraction of the run before RSS is judged (0.2)')
    parser.add_argument('--tolerance', type=float, default=0.02,
                        help='largest RSS growth after the warm-up (0.02)')
    parser.add_argument('--asan', action='store_true',
                        help='the binary has ASan: judge its leak report, not its RSS')
    args = parser.parse_args()
    return run_demo(args) if args.what == 'demo' else run_gui(args)


if __name__ == '__main__':
    sys.exit(main())

#!/usr/bin/env node
// The browser GUI's responsiveness on a slow page: starts `saccade gui`, opens its page in
// headless Chromium (SwiftShader WebGL, as web/tests/gui.test.mjs does), slows the page's CPU
// down with Chromium's throttling (DevTools' "CPU: N x slowdown"), and measures over --seconds:
//   - the frames per second each camera view showed;
//   - the round trip of `ping` sent from the page (median, max): what a command waits for,
//     behind whatever the page has not yet handled;
//   - the page's long tasks (over 50 ms of its main thread): how many a second, their share of
//     the time and the longest: what a click or a key waits for;
//   - what the server sent, skipped and had acknowledged for the page (/api/status).
//
//   node bench/gui_page.mjs [--throttle 4] [--seconds 10] [--pings 10] [--window N]
//                           [--scene FILE] [--binary build/bin/saccade] [--json]
//
// --window N opens the page with ?frame_window=N (the page's default is 4; 0: none).
//
// Needs `npm ci` in web/ (the README's setup does it) and Debian's chromium.
import { spawn } from 'node:child_process';
import { createRequire } from 'node:module';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { parseArgs } from 'node:util';

const repo = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
const { chromium } = createRequire(path.join(repo, 'web', 'package.json'))('playwright-core');

const { values: args } = parseArgs({
  options: {
    throttle: { type: 'string', default: '4' },
    seconds: { type: 'string', default: '10' },
    pings: { type: 'string', default: '10' },
    window: { type: 'string', default: '' },
    scene: { type: 'string', default: path.join(repo, 'scenes', 'portraits.yaml') },
    binary: { type: 'string', default: path.join(repo, 'build', 'bin', 'saccade') },
    json: { type: 'boolean', default: false },
    help: { type: 'boolean', default: false },
  },
});
if (args.help) {
  console.log('usage: node bench/gui_page.mjs [--throttle N] [--seconds S] [--pings N] [--scene FILE] ' +
    '[--binary PATH] [--json]\n(the file comment says what it measures)');
  process.exit(0);
}
const throttle = Number(args.throttle), seconds = Number(args.seconds), pings = Number(args.pings);
for (const [name, value] of [['--throttle', throttle], ['--seconds', seconds], ['--pings', pings]]) {
  if (!(value >= 1)) {
    console.error(`gui_page: ${name} must be a number >= 1, got '${args[name.slice(2)]}'`);
    process.exit(2);
  }
}

const server = spawn(args.binary, ['gui', '--scene', args.scene, '--port', '0'],
  { stdio: ['ignore', 'pipe', 'inherit'] });
const url = await new Promise((resolve, reject) => {
  let out = '';
  server.stdout.on('data', (d) => {
    out += d;
    const m = out.match(/^gui: .*?(http:\/\/\S+)/m);
    if (m) { server.stdout.resume(); resolve(m[1]); }
  });
  server.on('error', (e) => reject(new Error(`gui_page: cannot run ${args.binary}: ${e.message}`)));
  server.on('exit', (code) => reject(new Error(`gui_page: saccade gui exited (${code}) before serving`)));
}).catch((e) => {
  console.error(e.message);
  process.exit(1);
});

const browser = await chromium.launch({
  executablePath: '/usr/bin/chromium',
  args: ['--headless=new', '--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
    '--ignore-gpu-blocklist', '--disable-renderer-backgrounding', '--disable-background-timer-throttling'],
});
try {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  await page.goto(args.window === '' ? url
    : url + (url.includes('?') ? '&' : '?') + `frame_window=${encodeURIComponent(args.window)}`);
  console.error('gui_page: waiting for the page (scene, models, first frames)...');
  await page.waitForFunction(() => window.saccadeGui?.ready, null, { timeout: 180_000, polling: 200 });
  const cdp = await page.context().newCDPSession(page);
  await cdp.send('Emulation.setCPUThrottlingRate', { rate: throttle });
  console.error(`gui_page: page ready; CPU slowed down ${throttle} x, counting frames for ${seconds} s...`);
  // The page's long tasks (over 50 ms of its main thread, the Long Tasks API): what a click
  // or a key waits for behind them.
  await page.evaluate(() => {
    window.benchLongTasks = [];
    new PerformanceObserver((list) => {
      for (const entry of list.getEntries()) window.benchLongTasks.push(entry.duration);
    }).observe({ type: 'longtask' });
  });
  const shown0 = await page.evaluate(() => ({ ...window.saccadeGui.framesShown }));
  await page.waitForTimeout(seconds * 1000);
  const shown1 = await page.evaluate(() => ({ ...window.saccadeGui.framesShown }));
  const longTasks = (await page.evaluate(() => window.benchLongTasks.splice(0))).sort((a, b) => a - b);
  const roundTrips = [];
  for (let i = 0; i < pings; i++) {
    roundTrips.push(await page.evaluate(async () => {
      const t = performance.now();
      const reply = await window.saccadeGui.send('ping');
      if (reply.type !== 'reply') throw new Error(JSON.stringify(reply));
      return performance.now() - t;
    }));
  }
  const me = await page.evaluate(async () => {
    const status = await (await fetch('/api/status' + location.search)).json();
    return status.clients.find((c) => c.id === window.saccadeGui.hello.client);
  });
  roundTrips.sort((a, b) => a - b);
  const result = {
    throttle, seconds,
    shown_per_s: { left: (shown1.left - shown0.left) / seconds, right: (shown1.right - shown0.right) / seconds },
    ping_ms: { median: roundTrips[Math.floor(roundTrips.length / 2)], max: roundTrips[roundTrips.length - 1] },
    long_tasks: {
      per_s: longTasks.length / seconds,
      busy_share: longTasks.reduce((a, b) => a + b, 0) / (seconds * 1000),
      max_ms: longTasks.length ? longTasks[longTasks.length - 1] : 0,
    },
    server: { frames_sent: me.frames_sent, frames_skipped: me.frames_skipped, frame_window: me.frame_window,
      frames_acked: me.frames_acked },
  };
  if (args.json) {
    console.log(JSON.stringify(result, null, 2));
  } else {
    console.log(`page slowed down ${throttle} x: shown ${result.shown_per_s.left.toFixed(1)} / ` +
      `${result.shown_per_s.right.toFixed(1)} frames/s (left / right); ping round trip median ` +
      `${result.ping_ms.median.toFixed(1)} ms, max ${result.ping_ms.max.toFixed(1)}; long tasks ` +
      `${result.long_tasks.per_s.toFixed(1)}/s, ${(100 * result.long_tasks.busy_share).toFixed(0)} % of the ` +
      `time, longest ${result.long_tasks.max_ms.toFixed(0)} ms; server: ` +
      `${me.frames_sent} frames sent, ${me.frames_skipped} skipped, window ${me.frame_window}, ` +
      `${me.frames_acked} acknowledged`);
  }
} finally {
  await browser.close();
  server.kill('SIGTERM');
}

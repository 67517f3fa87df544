// Browser tests of saccade's GUI (issue 6): Debian's Chromium, driven by playwright-core,
// against the real simulator (`saccade gui --scene scenes/portraits.yaml`). WebGL runs on
// SwiftShader and the simulator on llvmpipe, so every wait is generous.
//
//   node --test --test-reporter=spec web/tests/gui.test.mjs
//
// SACCADE_BINARY: the saccade binary (default build/bin/saccade in the repository).
// SACCADE_UPDATE_REFERENCE=1: rewrite web/tests/reference/world.png from this run.
// Prints a line starting "figures:" with the streaming figures (frames per second per
// camera, ping and joints-to-state latencies).
import { after, before, describe, test } from 'node:test';
import assert from 'node:assert/strict';
import { spawn, spawnSync } from 'node:child_process';
import fs from 'node:fs';
import http from 'node:http';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

const kRepo = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..');
const kBinary = process.env.SACCADE_BINARY || path.join(kRepo, 'build', 'bin', 'saccade');
const kScene = path.join(kRepo, 'scenes', 'portraits.yaml');
const kMapPipeline = path.join(kRepo, 'pipelines', 'debug_map.yaml');
const kReference = path.join(kRepo, 'web', 'tests', 'reference', 'world.png');
const kOutput = fs.mkdtempSync(path.join(os.tmpdir(), 'saccade-gui-test-'));
const kViewport = { width: 1280, height: 800 };
const kDeg = Math.PI / 180;

// Tolerances.
const kStartTimeoutMs = 120_000;   // the simulator's start (scene load, GL context)
const kReadyTimeoutMs = 180_000;   // scene, models, textures, first state and frames
const kMoveTimeoutMs = 90_000;     // a commanded motion at a few simulation steps per second
// The world view against its reference: JPEG noise in the live image planes, the sensor noise,
// SwiftShader's rasterization: a mean absolute difference per channel below this (of 255),
// and at least kWorldInlierFraction of the pixels within kWorldPixelTolerance.
const kWorldMeanTolerance = 12;
const kWorldPixelTolerance = 40;
const kWorldInlierFraction = 0.9;
const kDragPx = 100;
const kDragAngleToleranceDeg = 4;  // the mouse lands on whole pixels; the throttle sends the last
const kImagePlaneTolerance = 3;   // mean grey difference (of 255), image plane against the view
const kImageChangeThreshold = 8;   // mean absolute grey difference (of 255) after a 50 deg pan
const kFixationToleranceDeg = 1.0; // each optical axis to the clicked point
// The sRGB tone curve lifts the realistic eyes' mid-tones (linear 0.2 encodes as 0.48): with the
// colour off the image is the linear RGB, darker by far more than this mean grey (of 255).
const kColourOffDarkening = 10;
const kFramesAfterSwitch = 3;      // frames shown after a switch before its image is read
const kRealisticScene = path.join(kRepo, 'scenes', 'portraits_realistic.yaml');

const kChromiumArgs = ['--headless=new', '--no-sandbox', '--disable-background-networking',
  '--disable-component-update', '--disable-sync', '--no-first-run', '--disable-quic',
  '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist',
  '--disable-renderer-backgrounding', '--disable-background-timer-throttling'];

/** Starts `saccade ARGS`; resolves {process, url, port} at its "gui: ... http://..." line. */
function startSaccade(args) {
  return new Promise((resolve, reject) => {
    const child = spawn(kBinary, args, { stdio: ['ignore', 'pipe', 'pipe'] });
    let stdout = '', stderr = '';
    const timer = setTimeout(() => {
      child.kill('SIGKILL');
      reject(new Error(`saccade ${args.join(' ')}: no "gui:" line in ${kStartTimeoutMs} ms\n${stdout}\n${stderr}`));
    }, kStartTimeoutMs);
    child.stderr.on('data', (d) => { stderr += d; });
    child.stdout.on('data', (d) => {
      stdout += d;
      const line = stdout.split('\n').find((l) => l.startsWith('gui: ') && /https?:\/\/\S+/.test(l));
      if (!line) return;
      clearTimeout(timer);
      const url = new URL(line.match(/https?:\/\/\S+/)[0]);
      child.stdout.removeAllListeners('data');
      child.stdout.resume();
      resolve({ process: child, url, port: Number(url.port), stderr: () => stderr });
    });
    child.on('error', (e) => { clearTimeout(timer); reject(e); });
    child.on('exit', (code, signal) => {
      clearTimeout(timer);
      reject(new Error(`saccade ${args.join(' ')} exited (${code ?? signal}) before its "gui:" line\n${stdout}\n${stderr}`));
    });
  });
}

/** SIGTERM, then SIGKILL if it has not exited within 15 s. */
async function stopSaccade(server) {
  if (!server || server.process.exitCode !== null || server.process.signalCode !== null) return;
  const exited = new Promise((resolve) => server.process.once('exit', resolve));
  server.process.kill('SIGTERM');
  const timer = setTimeout(() => server.process.kill('SIGKILL'), 15_000);
  await exited;
  clearTimeout(timer);
}

/** The page's address on 127.0.0.1 with the given query (the printed host may be 0.0.0.0). */
function localUrl(server, query = '') {
  return `http://127.0.0.1:${server.port}/${query}`;
}

async function openPage(browser, url) {
  const page = await browser.newPage({ viewport: kViewport });
  page.on('pageerror', (e) => console.log(`page error: ${e.message}`));
  await page.goto(url);
  return page;
}

async function waitReady(page) {
  await page.waitForFunction(() => window.saccadeGui?.ready || window.saccadeGui?.fatal,
    null, { timeout: kReadyTimeoutMs, polling: 200 });
  const fatal = await page.evaluate(() => window.saccadeGui.fatal);
  assert.equal(fatal, undefined, `the page failed: ${fatal}`);
  // Everything the page received so far conformed to the protocol (protocol.js checks each).
  const checked = await page.evaluate(() => ({
    refused: window.saccadeGui.protocolErrors, checked: window.saccadeGui.messagesChecked }));
  assert.deepEqual(checked.refused, [], 'messages of the server that break docs/gui-protocol.md');
  assert.ok(checked.checked > 0, 'the page checked no message');
}

/** Sends a command from the page's WebSocket; resolves with the reply or error. */
function send(page, type, fields = {}) {
  return page.evaluate(([t, f]) => window.saccadeGui.send(t, f), [type, fields]);
}

/** Waits until the page's latest state satisfies `predicate(state, arg)` (run in the page). */
async function waitState(page, predicate, arg, timeout = kMoveTimeoutMs) {
  await page.waitForFunction(([source, a]) => {
    const s = window.saccadeGui.state;
    // eslint-disable-next-line no-new-func
    return s && new Function('s', 'arg', `return (${source})(s, arg);`)(s, a);
  }, [predicate.toString(), arg], { timeout, polling: 50 });
  return page.evaluate(() => window.saccadeGui.state);
}

/** Commands the head to `joints` (rad, manual) and waits until it is there. */
async function moveHead(page, joints) {
  const reply = await send(page, 'joints', { positions: joints });
  assert.equal(reply.type, 'reply', `joints: ${JSON.stringify(reply)}`);
  return waitState(page, (s, j) => Object.entries(j).every(
    ([k, v]) => Math.abs(s.joints.positions[k] - v) < 0.2 * Math.PI / 180), joints);
}

/** The effect switches' state in the page: disabled, checked and tooltip of each. */
function effectBoxes(page) {
  return page.evaluate(() => Object.fromEntries(['distortion', 'noise', 'blur', 'optics', 'color']
    .map((k) => {
      const box = document.getElementById(`fx-${k}`);
      return [k, { disabled: box.disabled, checked: box.checked, title: box.parentElement.title }];
    })));
}

/** Waits until the page has shown `count` more frames of `camera` than now. */
async function waitFrames(page, camera, count) {
  const shown = await page.evaluate((n) => window.saccadeGui.framesShown[n], camera);
  await page.waitForFunction(([n, target]) => window.saccadeGui.framesShown[n] >= target,
    [camera, shown + count], { timeout: kMoveTimeoutMs, polling: 50 });
}

/** A grey 256 x 192 copy of a camera view's current image, as a plain array. */
function grabGrey(page, camera) {
  return page.evaluate((name) => {
    const view = document.getElementById(`image-${name}`);
    const c = document.createElement('canvas');
    c.width = 256; c.height = 192;
    const ctx = c.getContext('2d');
    ctx.drawImage(view, 0, 0, c.width, c.height);
    const d = ctx.getImageData(0, 0, c.width, c.height).data;
    const grey = [];
    for (let i = 0; i < d.length; i += 4) grey.push((d[i] + d[i + 1] + d[i + 2]) / 3);
    return grey;
  }, camera);
}

const meanAbsDiff = (a, b) => a.reduce((sum, v, i) => sum + Math.abs(v - b[i]), 0) / a.length;
const median = (xs) => [...xs].sort((a, b) => a - b)[Math.floor(xs.length / 2)];

/**
 * Compares two PNGs (base64) in the page: the mean absolute difference per channel, the
 * fraction of pixels whose channels all lie within `tolerance`, and a diff image (PNG base64).
 */
function comparePngs(page, actual, reference, tolerance) {
  return page.evaluate(async ([a, r, tol]) => {
    const load = async (b64) => {
      const blob = await (await fetch(`data:image/png;base64,${b64}`)).blob();
      const bitmap = await createImageBitmap(blob);
      const c = document.createElement('canvas');
      c.width = bitmap.width; c.height = bitmap.height;
      const ctx = c.getContext('2d');
      ctx.drawImage(bitmap, 0, 0);
      return ctx.getImageData(0, 0, c.width, c.height);
    };
    const [A, R] = await Promise.all([load(a), load(r)]);
    if (A.width !== R.width || A.height !== R.height) {
      return { sizeMismatch: `${A.width}x${A.height} vs ${R.width}x${R.height}` };
    }
    const c = document.createElement('canvas');
    c.width = A.width; c.height = A.height;
    const ctx = c.getContext('2d');
    const diff = ctx.createImageData(A.width, A.height);
    let sum = 0, inliers = 0;
    for (let i = 0; i < A.data.length; i += 4) {
      let worst = 0;
      for (let k = 0; k < 3; k++) {
        const d = Math.abs(A.data[i + k] - R.data[i + k]);
        sum += d;
        worst = Math.max(worst, d);
        diff.data[i + k] = Math.min(255, 4 * d);
      }
      diff.data[i + 3] = 255;
      if (worst <= tol) inliers++;
    }
    ctx.putImageData(diff, 0, 0);
    const pixels = A.width * A.height;
    return {
      mean: sum / (3 * pixels), inlierFraction: inliers / pixels,
      diff: c.toDataURL('image/png').split(',')[1],
    };
  }, [actual.toString('base64'), reference.toString('base64'), tolerance]);
}

describe('saccade gui (portraits.yaml)', () => {
  let browser, server, page;

  before(async () => {
    browser = await chromium.launch({ executablePath: '/usr/bin/chromium', args: kChromiumArgs });
    fs.mkdirSync(path.join(kOutput, 'recordings'), { recursive: true });
    server = await startSaccade(['gui', '--scene', kScene, '--port', '0',
      '--record-dir', path.join(kOutput, 'recordings')]);
    page = await openPage(browser, server.url.href);
  });

  after(async () => {
    await page?.close().catch(() => {});
    await browser?.close().catch(() => {});
    await stopSaccade(server);
    // The Record button's files (tens of MB a run): the pictures beside them stay for people.
    fs.rmSync(path.join(kOutput, 'recordings'), { recursive: true, force: true });
  });

  test('the page loads, draws the world and shows both cameras', async () => {
    await waitReady(page);
    // Both camera views: images of the cameras' size, not uniform. Both views' canvases must
    // hold a picture when they are read (0 x 0 until the first): the page waits for that.
    const views = await page.evaluate(async (timeoutMs) => {
      const decoded = () => ['left', 'right'].every(
        (n) => document.getElementById(`image-${n}`).width > 0);
      const until = performance.now() + timeoutMs;
      while (!decoded() && performance.now() < until) {
        await new Promise((resolve) => setTimeout(resolve, 10));
      }
      return ['left', 'right'].map((name) => {
        const view = document.getElementById(`image-${name}`);
        const camera = window.saccadeGui.scene.cameras.find((c) => c.name === name);
        const c = document.createElement('canvas');
        c.width = 128; c.height = 96;
        const ctx = c.getContext('2d');
        ctx.drawImage(view, 0, 0, c.width, c.height);
        const d = ctx.getImageData(0, 0, c.width, c.height).data;
        let sum = 0, sum2 = 0, n = 0;
        for (let i = 0; i < d.length; i += 4) {
          const g = (d[i] + d[i + 1] + d[i + 2]) / 3;
          sum += g; sum2 += g * g; n++;
        }
        const mean = sum / n;
        return { name, imageWidth: view.width, imageHeight: view.height,
          width: camera.width, height: camera.height, std: Math.sqrt(sum2 / n - mean * mean) };
      });
    }, kMoveTimeoutMs);
    for (const v of views) {
      assert.equal(v.imageWidth, v.width, `${v.name}: image width`);
      assert.equal(v.imageHeight, v.height, `${v.name}: image height`);
      assert.ok(v.std > 10, `${v.name}: the image is uniform (grey standard deviation ${v.std.toFixed(1)})`);
    }

    // A fixed state: manual, the head at home, paused; a fixed view.
    await send(page, 'perception', { enabled: false });
    await send(page, 'resume');
    await moveHead(page, { pan: 0, tilt: 0, left: 0, right: 0 });
    const paused = await send(page, 'pause');
    assert.equal(paused.type, 'reply', `pause: ${JSON.stringify(paused)}`);
    const shown = await page.evaluate(() => ({ ...window.saccadeGui.framesShown }));
    await page.waitForTimeout(1500);  // the last frames of the paused clock arrive
    await page.evaluate(() => {
      window.saccadeGui.setImageDistance(0.3);
      window.saccadeGui.setView([-1.5, -0.7, 2.1], [1.0, 0.0, 1.0]);
    });
    assert.ok(shown.left > 0 && shown.right > 0);
    // Each image plane in the world holds its camera view's picture, the right way up: both
    // scaled to 128 x 96, the mean grey difference is small, and far smaller than against the
    // picture upside down.
    const planes = await page.evaluate(async (timeoutMs) => {
      const settled = () => ['left', 'right'].every(
        (n) => document.getElementById(`image-${n}`).width > 0 && window.saccadeGui.imagePlane(n)?.visible);
      const until = performance.now() + timeoutMs;
      while (!settled() && performance.now() < until) {
        await new Promise((resolve) => setTimeout(resolve, 10));
      }
      const grey = (source, flip) => {
        const c = document.createElement('canvas');
        c.width = 128; c.height = 96;
        const ctx = c.getContext('2d');
        if (flip) ctx.setTransform(1, 0, 0, -1, 0, c.height);
        ctx.drawImage(source, 0, 0, c.width, c.height);
        const d = ctx.getImageData(0, 0, c.width, c.height).data;
        const g = new Float32Array(c.width * c.height);
        for (let i = 0; i < g.length; i++) g[i] = (d[4 * i] + d[4 * i + 1] + d[4 * i + 2]) / 3;
        return g;
      };
      const meanDiff = (a, b) => a.reduce((sum, v, i) => sum + Math.abs(v - b[i]), 0) / a.length;
      return ['left', 'right'].map((name) => {
        const plane = window.saccadeGui.imagePlane(name);
        const view = grey(document.getElementById(`image-${name}`), false);
        const flipped = grey(document.getElementById(`image-${name}`), true);
        const shownInWorld = grey(plane.canvas, false);
        return { name, settled: settled(), same: meanDiff(shownInWorld, view),
          upsideDown: meanDiff(shownInWorld, flipped) };
      });
    }, kMoveTimeoutMs);
    for (const p of planes) {
      const line = `${p.name} image plane against its camera view: mean grey difference ` +
        `${p.same.toFixed(2)} (against the view upside down ${p.upsideDown.toFixed(2)})`;
      console.log(line);
      assert.ok(p.settled, `${p.name}: the image plane never showed the view's picture`);
      assert.ok(p.same < kImagePlaneTolerance, line);
      assert.ok(p.upsideDown > 4 * p.same, line);
    }
    const actual = await page.locator('#world-canvas').screenshot();
    const actualPath = path.join(kOutput, 'world.actual.png');
    fs.writeFileSync(actualPath, actual);
    if (process.env.SACCADE_UPDATE_REFERENCE === '1') {
      fs.mkdirSync(path.dirname(kReference), { recursive: true });
      fs.writeFileSync(kReference, actual);
      console.log(`world reference written: ${kReference}`);
    }
    const result = await comparePngs(page, actual, fs.readFileSync(kReference), kWorldPixelTolerance);
    assert.equal(result.sizeMismatch, undefined, `world view size: ${result.sizeMismatch}`);
    const diffPath = path.join(kOutput, 'world.diff.png');
    fs.writeFileSync(diffPath, Buffer.from(result.diff, 'base64'));
    const report = `world view against ${kReference}: mean ${result.mean.toFixed(2)}, ` +
      `${(100 * result.inlierFraction).toFixed(1)} % within ${kWorldPixelTolerance} ` +
      `(actual ${actualPath}, diff ${diffPath})`;
    console.log(report);
    assert.ok(result.mean < kWorldMeanTolerance, report);
    assert.ok(result.inlierFraction > kWorldInlierFraction, report);
  });

  test('the optics and colour switches are disabled, saying why, when no camera has them', async () => {
    await waitReady(page);
    const boxes = await effectBoxes(page);
    for (const key of ['optics', 'color']) {
      assert.ok(boxes[key].disabled, `${key}: ${JSON.stringify(boxes[key])}`);
      assert.match(boxes[key].title, /^no camera of this scene has /);
    }
    for (const key of ['distortion', 'noise', 'blur']) assert.ok(!boxes[key].disabled, key);
  });

  test('the page places the world at the poses of the scene and the state, in their one form', async () => {
    await waitReady(page);
    const seen = await page.evaluate(() => {
      const g = window.saccadeGui;
      const s = g.state;  // the state the head was last placed from (same task)
      return {
        scene: {
          objects: g.scene.objects.map((o) => ({ name: o.name, X_WO: o.X_WO, scale: o.scale })),
          parts: (g.scene.robot?.parts ?? []).map((p) => p.X_LinkPart),
          cameras: g.scene.cameras.map((c) => c.X_WC),
        },
        frames: s.frames,
        stateObjects: s.objects,
        placed: {
          neck: g.placementOf('neck_link'),
          left_eye: g.placementOf('left_eye_link'),
          objects: Object.fromEntries(g.scene.objects.map((o) => [o.name, g.placementOf(o.name)])),
        },
      };
    });
    // geometry/json.h's one form (docs/gui-protocol.md): 4x4, row by row, last row [0, 0, 0, 1].
    const isPose = (X) => Array.isArray(X) && X.length === 4 &&
      X.every((row) => Array.isArray(row) && row.length === 4 && row.every(Number.isFinite)) &&
      X[3].join() === '0,0,0,1';
    const poses = [
      ...seen.scene.objects.map((o) => [`scene objects ${o.name} X_WO`, o.X_WO]),
      ...seen.scene.parts.map((X, i) => [`scene robot part ${i} X_LinkPart`, X]),
      ...seen.scene.cameras.map((X, i) => [`scene camera ${i} X_WC`, X]),
      ...Object.entries(seen.frames).filter(([k]) => k !== 'links')
        .map(([k, X]) => [`state frames ${k}`, X]),
      ...Object.entries(seen.frames.links).map(([k, X]) => [`state frames links ${k}`, X]),
      ...seen.stateObjects.map((o) => [`state objects ${o.name} X_WO`, o.X_WO]),
    ];
    assert.ok(seen.scene.objects.length > 0 && seen.scene.parts.length > 0 &&
      Object.keys(seen.frames).length === 5 && Object.keys(seen.frames.links).length >= 7,
      JSON.stringify(seen.frames));
    for (const [where, X] of poses) assert.ok(isPose(X), `${where}: ${JSON.stringify(X)}`);
    // The page puts each link at its frame and each object at X_WO * diag(scale): the page
    // reads the rows as rows (a transposed read would move every part).
    const kPlacementTolerance = 1e-12;  // three.js multiplies by the scale in doubles
    const near = (A, B, where) => {
      for (let r = 0; r < 4; r++) {
        for (let c = 0; c < 4; c++) {
          assert.ok(Math.abs(A[r][c] - B[r][c]) <= kPlacementTolerance,
            `${where} (${r}, ${c}): placed ${JSON.stringify(A)}, pose ${JSON.stringify(B)}`);
        }
      }
    };
    near(seen.placed.neck, seen.frames.links.neck_link, 'neck_link');
    near(seen.placed.left_eye, seen.frames.links.left_eye_link, 'left_eye_link');
    const moving = new Map(seen.stateObjects.map((o) => [o.name, o.X_WO]));
    for (const o of seen.scene.objects) {
      const X = moving.get(o.name) ?? o.X_WO;
      const expected = X.map((row, r) => row.map((v, c) => (c < 3 && r < 4 ? v * o.scale[c] : v)));
      near(seen.placed.objects[o.name], expected, `object ${o.name}`);
    }
  });

  test('a camera view finishes with every frame: shown, undecodable or replaced', async () => {
    // The frame window (docs/gui-protocol.md) counts on it: a frame the view never finishes
    // with would hold the server's window shut. A view of its own, in the page.
    const result = await page.evaluate(async (timeoutMs) => {
      const { CameraView } = await import('/app/views.js');
      const canvas = document.createElement('canvas');
      let shown = 0, done = 0;
      const view = new CameraView(canvas, document.createElement('span'), 'test',
        () => shown++, () => done++);
      const source = document.createElement('canvas');
      source.width = 8; source.height = 6;
      source.getContext('2d').fillRect(0, 0, 8, 6);
      const jpeg = await new Promise((resolve) => source.toBlob(resolve, 'image/jpeg'));
      const header = (frame) => ({ width: 8, height: 6, frame, time: 0 });
      view.frame(header(1), new Blob(['not a JPEG'], { type: 'image/jpeg' }));
      view.frame(header(2), jpeg);  // waits for frame 1, then is replaced by 3
      view.frame(header(3), jpeg);
      const until = performance.now() + timeoutMs;
      while (done < 3 && performance.now() < until) {
        await new Promise((r) => setTimeout(r, 10));
      }
      return { shown, done, failed: view.failed, width: canvas.width, height: canvas.height };
    }, 10_000);
    assert.deepEqual(result, { shown: 1, done: 3, failed: 1, width: 8, height: 6 });
  });

  test('the Record button records every topic to an MCAP file that saccade mcap info reads', async () => {
    await waitReady(page);
    await send(page, 'resume');
    await page.click('#record');
    const s = await waitState(page, (st) => st.recording && st.recording.megabytes > 0);
    assert.match(await page.locator('#record').innerText(), /Stop recording \([0-9.]+ MB\)/);
    const step = s.step;
    await waitState(page, (st, n) => st.step >= n + 3, step);
    await page.click('#record');
    await waitState(page, (st) => st.recording === null);
    assert.match(await page.locator('#record').innerText(), /Record/);
    const file = s.recording.file;
    assert.equal(path.dirname(file), path.join(kOutput, 'recordings'));
    assert.match(path.basename(file), /^saccade-\d{8}-\d{6}(-\d+)?\.mcap$/);
    const info = spawnSync(kBinary, ['mcap', 'info', '--json', file], { encoding: 'utf8' });
    assert.equal(info.status, 0, info.stderr);
    const report = JSON.parse(info.stdout);
    assert.equal(report.complete, true, 'closed with its summary');
    const channels = Object.fromEntries(report.channels.map((c) => [c.topic, c]));
    assert.equal(channels['/saccade/left/image_raw'].type, 'sensor_msgs/msg/Image');
    assert.ok(channels['/saccade/left/image_raw'].messages >= 3, JSON.stringify(channels));
    assert.ok(channels['/saccade/joint_states'].messages >= 3);
    assert.equal(report.metadata.saccade.command, 'gui');
  });

  test('a joints command outside the limits is refused and moves nothing', async () => {
    await waitReady(page);
    const before = await page.evaluate(() => window.saccadeGui.state.joints.targets.pan);
    const step = await page.evaluate(() => window.saccadeGui.state.step);
    const reply = await send(page, 'joints', { positions: { pan: 3.0 } });
    assert.equal(reply.type, 'error', `joints pan 3 rad: ${JSON.stringify(reply)}`);
    assert.match(reply.error, /pan/, 'the error names the joint');
    assert.ok(await page.evaluate((id) => window.saccadeGui.errors.some((e) => e.id === id), reply.id),
      'the error is in the page\'s list');
    assert.match(await page.locator('#log').innerText(), /pan/, 'the error is shown in the log');
    await send(page, 'resume');
    const s = await waitState(page, (st, n) => st.step >= n + 3, step);
    assert.ok(Math.abs(s.joints.targets.pan - before) < 1e-9, `pan target ${s.joints.targets.pan} was ${before}`);
    assert.ok(Math.abs(s.joints.positions.pan) < Math.PI / 2 + 1e-6);
  });

  test('dragging the neck pans the head', async () => {
    await waitReady(page);
    await send(page, 'resume');
    await moveHead(page, { pan: 0, tilt: 0, left: 0, right: 0 });
    await page.evaluate(() => window.saccadeGui.setView([-1.5, -0.7, 2.1], [1.0, 0.0, 1.0]));
    const framesBefore = await page.evaluate(() => window.saccadeGui.framesShown.left);
    await page.waitForFunction((n) => window.saccadeGui.framesShown.left > n + 1, framesBefore,
      { timeout: kMoveTimeoutMs });
    const imageBefore = await grabGrey(page, 'left');

    const p = await page.evaluate(() => window.saccadeGui.screenPointOf('neck_link'));
    assert.ok(p.visible, `the neck is hidden in the view (${JSON.stringify(p)})`);
    const gain = await page.evaluate(() => window.saccadeGui.dragGainDegPerPx);
    await page.mouse.move(p.x, p.y);
    await page.mouse.down();
    for (let i = 1; i <= 20; i++) {
      await page.mouse.move(p.x + (kDragPx * i) / 20, p.y);
      await page.waitForTimeout(30);
    }
    await page.mouse.up();
    // Seen from behind the head, a drag to the right turns it right: pan decreases.
    const expected = -gain * kDragPx * kDeg;
    let s;
    try {
      s = await waitState(page, (st, { e, tol }) => Math.abs(st.joints.targets.pan - e) < tol,
        { e: expected, tol: kDragAngleToleranceDeg * kDeg });
    } catch {
      s = await page.evaluate(() => window.saccadeGui.state);
    }
    const pan = s.joints.targets.pan;
    const limits = await page.evaluate(() => window.saccadeGui.scene.head.joints.find((j) => j.name === 'pan'));
    assert.ok(Math.abs(pan - expected) < kDragAngleToleranceDeg * kDeg,
      `pan target ${(pan / kDeg).toFixed(1)} deg, expected ${(expected / kDeg).toFixed(1)} deg`);
    assert.ok(pan >= limits.min && pan <= limits.max);
    // The head gets there and the left camera sees something else.
    await waitState(page, (st) => Math.abs(st.joints.positions.pan - st.joints.targets.pan) < 0.01);
    const framesMoved = await page.evaluate(() => window.saccadeGui.framesShown.left);
    await page.waitForFunction((n) => window.saccadeGui.framesShown.left > n + 2, framesMoved,
      { timeout: kMoveTimeoutMs });
    const difference = meanAbsDiff(imageBefore, await grabGrey(page, 'left'));
    assert.ok(difference > kImageChangeThreshold,
      `the left image changed by ${difference.toFixed(1)} (mean absolute grey), expected > ${kImageChangeThreshold}`);
  });

  test('clicking a portrait fixates it', async () => {
    await waitReady(page);
    await send(page, 'resume');
    await moveHead(page, { pan: 0, tilt: 0, left: 0, right: 0 });
    await page.evaluate(() => window.saccadeGui.setView([-1.5, -0.7, 2.1], [1.0, 0.0, 1.0]));
    const p = await page.evaluate(() => window.saccadeGui.screenPointOf('astronaut_near'));
    assert.ok(p.visible, `astronaut_near is hidden in the view (${JSON.stringify(p)})`);
    const errorsBefore = await page.evaluate(() => window.saccadeGui.errors.length);
    await page.mouse.click(p.x, p.y);
    await page.waitForFunction(() => window.saccadeGui.lastClick, null, { timeout: 10_000 });
    const click = await page.evaluate(() => window.saccadeGui.lastClick);
    // Each optical axis (z column of X_WC) against the direction to the clicked point.
    const axisErrors = (s, q) => ['left', 'right'].map((name) => {
      const m = s.frames[name];
      const d = [q[0] - m[0][3], q[1] - m[1][3], q[2] - m[2][3]];
      const n = Math.hypot(...d);
      const cos = (m[0][2] * d[0] + m[1][2] * d[1] + m[2][2] * d[2]) / n;
      return Math.acos(Math.min(1, cos)) * 180 / Math.PI;
    });
    // The head turns to it (new targets) and gets there (positions at the targets).
    let s;
    try {
      s = await waitState(page, (st) => {
        const { positions: p, targets: t } = st.joints;
        return Math.abs(t.pan) + Math.abs(t.tilt) > 1e-3 &&
          ['pan', 'tilt', 'left', 'right'].every((k) => Math.abs(p[k] - t[k]) < 0.02 * Math.PI / 180);
      }, null, 60_000);
    } catch (e) {
      s = await page.evaluate(() => window.saccadeGui.state);
      const errors = await page.evaluate((n) => window.saccadeGui.errors.slice(n), errorsBefore);
      assert.fail(`not fixated in 60 s: axis errors ${axisErrors(s, click).map((x) => x.toFixed(2))} deg, ` +
        `joints ${JSON.stringify(s.joints)}; errors ${JSON.stringify(errors)}`);
    }
    const errors = axisErrors(s, click);
    console.log(`fixated [${click.map((v) => v.toFixed(3))}]: axis errors ${errors.map((x) => x.toFixed(3))} deg`);
    for (const e of errors) assert.ok(e < kFixationToleranceDeg, `axis errors ${errors} deg`);
  });

  test('a message that breaks the protocol is refused by the page, the field named', async () => {
    // A page of its own (the refusals stay there), fed a state and a frame that break
    // docs/gui-protocol.md as if the server had sent them.
    const other = await openPage(browser, server.url.href);
    await other.waitForFunction(() => window.saccadeGui?.state?.joints, null,
      { timeout: kReadyTimeoutMs, polling: 200 });
    const result = await other.evaluate(() => {
      const g = window.saccadeGui;
      if (g.protocolErrors.length) throw new Error(`refused already: ${g.protocolErrors}`);
      const broken = structuredClone(g.state);
      broken.joints.positions.pan = 'left';
      g.connection.receive(JSON.stringify(broken));
      const header = new TextEncoder().encode(JSON.stringify(
        { type: 'frame', camera: 'left', frame: 1, time: 0, height: 48, overlay: true }));
      const buffer = new ArrayBuffer(4 + header.length + 2);
      new DataView(buffer).setUint32(0, header.length, true);
      new Uint8Array(buffer, 4).set(header);
      const received = g.framesReceived.left;
      g.connection.receive(buffer);
      return { refused: [...g.protocolErrors], pan: g.state.joints.positions.pan,
        framesReceived: g.framesReceived.left - received };
    });
    assert.deepEqual(result.refused, ["state: field 'joints.positions.pan' must be a number, got string",
      "frame: missing field 'width'"]);
    assert.equal(typeof result.pan, 'number', 'the broken state was applied');
    assert.equal(result.framesReceived, 0, 'the broken frame was shown');
    assert.match(await other.locator('#log').innerText(),
      /refused a message that breaks the protocol: state: field 'joints\.positions\.pan'/);
    await other.close();
  });

  test('figures: frames per second, ping and joints latency', async () => {
    await waitReady(page);
    await send(page, 'resume');
    const windowS = 10;
    const f0 = await page.evaluate(() => ({ ...window.saccadeGui.framesReceived }));
    await page.waitForTimeout(windowS * 1000);
    const f1 = await page.evaluate(() => ({ ...window.saccadeGui.framesReceived }));
    const fps = { left: (f1.left - f0.left) / windowS, right: (f1.right - f0.right) / windowS };
    const timing = await page.evaluate(() => window.saccadeGui.state.timing);
    const pings = [];
    for (let i = 0; i < 10; i++) {
      pings.push(await page.evaluate(async () => {
        const t = performance.now();
        const reply = await window.saccadeGui.send('ping');
        if (reply.type !== 'reply') throw new Error(JSON.stringify(reply));
        return performance.now() - t;
      }));
    }
    const joints = [];
    for (let i = 0; i < 10; i++) {
      const pan = (i % 2 ? 5 : -5) * kDeg + i * 1e-3;
      joints.push(await page.evaluate(async (target) => {
        const t = performance.now();
        const reply = await window.saccadeGui.send('joints', { positions: { pan: target } });
        if (reply.type !== 'reply') throw new Error(JSON.stringify(reply));
        for (;;) {
          const s = window.saccadeGui.state;
          if (Math.abs(s.joints.targets.pan - target) < 1e-6) return performance.now() - t;
          if (performance.now() - t > 30000) throw new Error('no state with the new target in 30 s');
          await new Promise((r) => setTimeout(r, 1));
        }
      }, pan));
    }
    const line = `figures: frames received per second over ${windowS} s: left ${fps.left.toFixed(1)}, ` +
      `right ${fps.right.toFixed(1)} (server: ${timing?.steps_per_s?.toFixed?.(1)} steps/s, ` +
      `${timing?.frames_per_s?.toFixed?.(1)} frames/s); ping round trip median ${median(pings).toFixed(1)} ms ` +
      `(min ${Math.min(...pings).toFixed(1)}); joints command to a state with the new target median ` +
      `${median(joints).toFixed(1)} ms (min ${Math.min(...joints).toFixed(1)}, max ${Math.max(...joints).toFixed(1)}); ` +
      `Chromium headless, SwiftShader, ${os.cpus().length} cores`;
    console.log(line);
    assert.ok(fps.left > 0 && fps.right > 0, line);

    // Flow control: the page asked for a window of frames and acknowledges each frame it is
    // done with, so the server never has more than the window of them unacknowledged.
    const flow = await page.evaluate(async () => {
      const response = await fetch('/api/status' + location.search);
      const status = await response.json();
      const me = status.clients.find((c) => c.id === window.saccadeGui.hello.client);
      return { me, done: window.saccadeGui.framesDone };
    });
    assert.ok(flow.me, 'the page is among /api/status clients');
    assert.equal(flow.me.frame_window, 4, JSON.stringify(flow.me));
    assert.ok(flow.me.frames_acked > 0 && flow.me.frames_acked <= flow.done, JSON.stringify(flow));
    assert.ok(flow.me.frames_sent - flow.me.frames_acked <= 4, JSON.stringify(flow.me));
  });
});

describe('a page of another origin (issue 18)', () => {
  let browser, server, evil;

  before(async () => {
    // evil.example.com resolves to this machine, as a DNS-rebinding name would.
    browser = await chromium.launch({ executablePath: '/usr/bin/chromium',
      args: [...kChromiumArgs, '--host-resolver-rules=MAP evil.example.com 127.0.0.1'] });
    server = await startSaccade(['gui', '--scene', kScene, '--port', '0']);
    // The foreign page, served from another origin on this machine.
    evil = http.createServer((req, res) => {
      res.writeHead(200, { 'Content-Type': 'text/html' });
      res.end('<!doctype html><title>evil</title><p>nothing to see');
    });
    await new Promise((resolve) => evil.listen(0, '127.0.0.1', resolve));
  });

  after(async () => {
    await browser?.close().catch(() => {});
    await stopSaccade(server);
    evil?.close();
  });

  test('cannot open the WebSocket, read the scene or move the head, even knowing the token', async () => {
    const token = server.url.searchParams.get('token');
    assert.match(token ?? '', /^[0-9a-f]{32}$/, `a random token in ${server.url.href}`);
    const own = await openPage(browser, server.url.href);
    await waitReady(own);
    const before = await own.evaluate(() => window.saccadeGui.state.joints.targets.pan);

    const attacker = await browser.newPage();
    for (const origin of [`http://127.0.0.1:${evil.address().port}/`,
                          `http://evil.example.com:${evil.address().port}/`]) {
      await attacker.goto(origin);
      const result = await attacker.evaluate(async ({ port, token }) => {
        const socket = await new Promise((resolve) => {
          const ws = new WebSocket(`ws://127.0.0.1:${port}/ws?token=${token}`);
          const r = { opened: false };
          ws.onopen = () => {
            r.opened = true;
            ws.send(JSON.stringify({ type: 'joints', id: 1, positions: { pan: 0.3 } }));
            setTimeout(() => resolve(r), 1000);
          };
          ws.onclose = () => resolve(r);
        });
        let read = null;
        try {
          read = (await fetch(`http://127.0.0.1:${port}/api/scene?token=${token}`)).status;
        } catch (e) {
          read = 'blocked';
        }
        return { socket, read };
      }, { port: server.port, token });
      assert.equal(result.socket.opened, false, `a page at ${origin} opened the WebSocket`);
      assert.equal(result.read, 'blocked', `a page at ${origin} read the scene`);
    }
    // DNS rebinding: the attacker's name now points at saccade itself.
    const rebound = await attacker.goto(`http://evil.example.com:${server.port}/api/scene?token=${token}`);
    assert.equal(rebound.status(), 403);
    const page = await attacker.goto(`http://evil.example.com:${server.port}/`);
    assert.equal(page.status(), 403);
    await attacker.close();

    // Nothing moved: two steps after the attack the pan target is what it was.
    const after = await own.evaluate(async (from) => {
      const t = performance.now();
      while (window.saccadeGui.state.step < from + 2 && performance.now() - t < 60000) {
        await new Promise((r) => setTimeout(r, 50));
      }
      return window.saccadeGui.state.joints.targets.pan;
    }, await own.evaluate(() => window.saccadeGui.state.step));
    assert.equal(after, before, 'the pan target changed');
    assert.ok(Math.abs(after - 0.3) > 1e-6);
    await own.close();
  });
});

describe('saccade gui with an access token', () => {
  let browser, server;

  before(async () => {
    browser = await chromium.launch({ executablePath: '/usr/bin/chromium', args: kChromiumArgs });
    server = await startSaccade(['gui', '--scene', kScene, '--listen', '0.0.0.0', '--port', '0',
      '--token', 's3cret']);
  });

  after(async () => {
    await browser?.close().catch(() => {});
    await stopSaccade(server);
  });

  test('without the token the page says so and nothing is served or executed', async () => {
    assert.match(server.url.search, /token=s3cret/, `the printed address ${server.url.href} carries the token`);
    // Plain HTTP: /api/ needs the token, in the query or as a bearer header.
    assert.equal((await fetch(localUrl(server, 'api/scene'))).status, 401);
    assert.equal((await fetch(localUrl(server, 'api/scene?token=wrong'))).status, 401);
    assert.equal((await fetch(localUrl(server, 'api/scene'), {
      headers: { Authorization: 'Bearer s3cret' } })).status, 200);

    const page = await openPage(browser, localUrl(server));
    await page.waitForFunction(() => window.saccadeGui?.accessDenied, null, { timeout: kReadyTimeoutMs });
    const text = await page.locator('#access').innerText();
    assert.match(text, /access token required/);
    assert.equal(await page.locator('#access').isVisible(), true);
    assert.equal(await page.locator('#layout').isVisible(), false, 'the empty GUI is hidden');
    // Raw WebSockets without (or with a wrong) token: refused; a command sent if one opened
    // anyway would show below as a paused clock or a moved pan target.
    const sockets = await page.evaluate(async (port) => Promise.all(['', '?token=wrong'].map((q) =>
      new Promise((resolve) => {
        const ws = new WebSocket(`ws://127.0.0.1:${port}/ws${q}`);
        const result = { query: q, opened: false, messages: 0 };
        ws.onopen = () => {
          result.opened = true;
          ws.send(JSON.stringify({ type: 'pause', id: 1 }));
          ws.send(JSON.stringify({ type: 'joints', id: 2, positions: { pan: 0.5 } }));
        };
        ws.onmessage = () => { result.messages++; };
        ws.onclose = () => resolve(result);
        setTimeout(() => { ws.close(); resolve(result); }, 5000);
      }))), server.port);
    for (const s of sockets) {
      assert.equal(s.opened, false, `WebSocket ${s.query || 'without token'} was accepted`);
      assert.equal(s.messages, 0);
    }
    assert.equal(await page.evaluate(() => window.saccadeGui.ready), false);
    await page.close();

    // With the token: ready, and nothing of the above happened.
    const good = await openPage(browser, localUrl(server, '?token=s3cret'));
    await waitReady(good);
    const state = await good.evaluate(() => window.saccadeGui.state);
    assert.equal(state.paused, false, 'a command without the token paused the simulation');
    assert.ok(Math.abs(state.joints.targets.pan - 0.5) > 1e-6, 'a command without the token moved the head');
    await good.close();
  });
});

describe('saccade gui restarted', () => {
  let browser, server;

  before(async () => {
    browser = await chromium.launch({ executablePath: '/usr/bin/chromium', args: kChromiumArgs });
  });

  after(async () => {
    await browser?.close().catch(() => {});
    await stopSaccade(server);
  });

  test('the page says it lost saccade, then reloads with the new scene when it is back', async () => {
    const twoPictures = path.join(kRepo, 'scenes', 'astronaut_and_cat.yaml');
    // The same token for both runs (as an operator keeps a bookmarked address across restarts);
    // without --token each run has a random one and the reloaded page would be refused.
    server = await startSaccade(['gui', '--scene', twoPictures, '--port', '0', '--token', 'keep']);
    const port = server.port;
    const page = await openPage(browser, localUrl(server, '?token=keep'));
    await waitReady(page);
    const names = async () => page.evaluate(() => window.saccadeGui.scene.objects.map((o) => o.name));
    assert.ok(!(await names()).includes('astronaut_near'));

    await stopSaccade(server);
    await page.waitForFunction(() => /disconnected/.test(document.getElementById('connection').textContent),
      null, { timeout: 30_000 });
    const reloaded = page.waitForEvent('load', { timeout: kReadyTimeoutMs });
    server = await startSaccade(['gui', '--scene', kScene, '--port', String(port), '--token', 'keep']);
    await reloaded;
    await waitReady(page);
    assert.ok((await names()).includes('astronaut_near'), 'the page shows the new scene');
    await page.close();
  });
});

// Realistic eyes (a Bayer mosaic, sRGB, vignetting, depth of field): the optics and colour
// switches are offered, and the colour switch changes the streamed camera image.
describe('saccade gui with realistic cameras (portraits_realistic.yaml)', () => {
  let browser, server, page;

  before(async () => {
    browser = await chromium.launch({ executablePath: '/usr/bin/chromium', args: kChromiumArgs });
    server = await startSaccade(['gui', '--scene', kRealisticScene, '--port', '0']);
    page = await openPage(browser, server.url.href);
  });

  after(async () => {
    await page?.close().catch(() => {});
    await browser?.close().catch(() => {});
    await stopSaccade(server);
  });

  test('switching the colour off shows the linear image, and back on the toned one', async () => {
    await waitReady(page);
    const boxes = await effectBoxes(page);
    for (const key of ['optics', 'color']) {
      assert.ok(!boxes[key].disabled && boxes[key].checked, `${key}: ${JSON.stringify(boxes[key])}`);
      assert.match(boxes[key].title, /of left, right$/);
    }
    const mean = (xs) => xs.reduce((a, b) => a + b, 0) / xs.length;
    await waitFrames(page, 'left', 1);
    // The label says the controls the frame was taken with (the file's 8 ms, 0 dB, 2 m focus).
    assert.match(await page.textContent('#label-left'), / · 8\.0 ms · 0\.0 dB · focus 2\.00 m$/);
    const toned = await grabGrey(page, 'left');
    // The page's switch sends the command; the state says it, the box follows.
    await page.click('#fx-color');
    const state = await waitState(page, (s) => s.effects && s.effects.color === false);
    assert.equal(state.effects.optics, true);
    await waitFrames(page, 'left', kFramesAfterSwitch);
    const linear = await grabGrey(page, 'left');
    console.log(`figures: realistic left eye mean grey ${mean(toned).toFixed(1)} with colour, ` +
      `${mean(linear).toFixed(1)} without`);
    assert.ok(mean(linear) < mean(toned) - kColourOffDarkening,
      `colour off: mean grey ${mean(linear).toFixed(1)}, on: ${mean(toned).toFixed(1)}`);
    assert.equal((await effectBoxes(page)).color.checked, false);
    await page.click('#fx-color');
    await waitState(page, (s) => s.effects && s.effects.color === true);
    await waitFrames(page, 'left', kFramesAfterSwitch);
    const again = await grabGrey(page, 'left');
    assert.ok(mean(again) > mean(linear) + kColourOffDarkening,
      `colour on again: mean grey ${mean(again).toFixed(1)}, off: ${mean(linear).toFixed(1)}`);
  });
});

// A head other than POPEYE: robots/humanoid.yaml put in place of the scene's by --head.
const kHumanoidHead = path.join(kRepo, 'robots', 'humanoid.yaml');
const kHumanoidUrdf = path.join(kRepo, 'robots', 'humanoid', 'humanoid.urdf');
const kHumanoidJoints = ['neck_pitch', 'neck_roll', 'neck_yaw', 'eye_tilt', 'left_eye_pan', 'right_eye_pan'];
// POPEYE's links and joints, none of which the humanoid has.
const kPopeyeLinks = ['neck_link', 'tilt_link', 'cyclopean_link', 'left_camera_optical', 'right_camera_optical'];
const kPopeyeJoints = ['pan', 'tilt', 'left', 'right', 'L', 'R'];
const kHumanoidDragPx = 20;           // 10 deg of neck yaw at the page's drag gain (0.5 deg/px)
const kHumanoidDragToleranceDeg = 1;  // two pixels of the drag: the mouse lands on whole pixels
const kSettledDeg = 0.05;             // a joint at its target: the servo settles far closer
const kPoseTolerance = 1e-9;          // a link the drag does not move: its frame, in doubles
const kYawAngleToleranceDeg = 0.1;    // the eyes turn with the neck's yaw: FK in doubles, settling
const kHumanoidFixationToleranceDeg = 0.5;  // each optical axis to the clicked point, settled
const kRobotCentreToleranceM = 0.3;   // the drawn body's box centre to the eyes: the head is ~0.3 m tall

/**
 * The URDF's links with their number of <visual>s, and its non-fixed joints, from the file
 * itself: what the page must draw and list.
 */
function readUrdf(file) {
  const text = fs.readFileSync(file, 'utf8').replace(/<!--[\s\S]*?-->/g, '');
  const visuals = {};
  for (const m of text.matchAll(/<link\s+name="([^"]+)"\s*(?:\/>|>([\s\S]*?)<\/link>)/g)) {
    visuals[m[1]] = (m[2] ?? '').match(/<visual[\s>]/g)?.length ?? 0;
  }
  const joints = [...text.matchAll(/<joint\s+name="([^"]+)"\s+type="([^"]+)"/g)]
    .filter((m) => m[2] !== 'fixed').map((m) => m[1]);
  return { visuals, joints };
}

/** The largest absolute difference between two 4x4 matrices (row by row). */
const maxAbsDiff = (A, B) => A.flat().reduce((m, v, i) => Math.max(m, Math.abs(v - B.flat()[i])), 0);

/** The rotation angle (deg) from rotation A to rotation B (4x4 poses, row by row): of B A^T. */
function rotationBetweenDeg(A, B) {
  let trace = 0;
  for (let i = 0; i < 3; i++) for (let k = 0; k < 3; k++) trace += B[i][k] * A[i][k];
  return Math.acos(Math.max(-1, Math.min(1, (trace - 1) / 2))) * 180 / Math.PI;
}

describe('saccade gui with a map (pipelines/debug_map.yaml: debug.map, a wall that grows)', () => {
  let browser, server, page;
  // debug.map's parameters in pipelines/debug_map.yaml.
  const kVoxelsPerStep = 20, kMaxVoxels = 2000, kResolution = 0.05, kRadius = 0.15;
  const kMapEverySteps = 5;   // the server's bound (gui/protocol.h kMapEverySteps)
  const kMaxOpacity = 0.6;    // map.js: a place of strength s is drawn at opacity 0.6 s

  before(async () => {
    browser = await chromium.launch({ executablePath: '/usr/bin/chromium', args: kChromiumArgs });
    server = await startSaccade(['gui', '--scene', kScene, '--pipeline', kMapPipeline, '--port', '0']);
    page = await openPage(browser, server.url.href);
  });

  after(async () => {
    await page?.close().catch(() => {});
    await browser?.close().catch(() => {});
    await stopSaccade(server);
  });

  test('the map appears in the 3D view and grows: its points, and its inhibited places as spheres', async () => {
    await waitReady(page);
    assert.deepEqual(await page.evaluate(() => window.saccadeGui.mapCounts().points), 0,
      'no map before the mapper runs (perception is off at start)');
    const on = await send(page, 'perception', { enabled: true });
    assert.equal(on.type, 'reply', JSON.stringify(on));
    await send(page, 'resume');
    // Counted from the page's 3D scene: the points object's vertices, the spheres' meshes.
    await page.waitForFunction(() => {
      const c = window.saccadeGui.mapCounts();
      return c.points >= 100 && c.inhibited >= 1;
    }, null, { timeout: kMoveTimeoutMs, polling: 100 });
    const first = await page.evaluate(() => window.saccadeGui.mapCounts());
    const m = first.message;
    // kVoxelsPerStep a step since perception came on, at most one per step of the run.
    assert.ok(m.total % kVoxelsPerStep === 0 && m.total <= Math.min(kMaxVoxels, kVoxelsPerStep * (m.frame + 1)),
      JSON.stringify(m));
    assert.equal(first.points, m.total, 'every voxel drawn (below the cap)');
    assert.equal(m.points, m.total);
    assert.ok(Math.abs(first.pointSize - kResolution) < 1e-9, `point size ${first.pointSize}`);
    assert.equal(first.inhibited, m.inhibited);
    for (const r of first.radii) assert.ok(Math.abs(r - kRadius) < 1e-9, `radius ${r}`);
    // Opacity follows strength: at most kMaxOpacity (just fixated), strongest first.
    for (const o of first.opacities) assert.ok(o > 0 && o <= kMaxOpacity + 1e-9, `opacity ${o}`);
    assert.deepEqual(first.opacities, [...first.opacities].sort((a, b) => b - a));

    // It grows, and the page is sent a map at most every kMapEverySteps steps.
    await page.waitForFunction((n) => window.saccadeGui.mapCounts().points > n, first.points,
      { timeout: kMoveTimeoutMs, polling: 100 });
    const later = await page.evaluate(() => ({
      counts: window.saccadeGui.mapCounts(), maps: window.saccadeGui.mapsReceived,
      step: window.saccadeGui.state.step, refused: window.saccadeGui.protocolErrors }));
    assert.ok(later.counts.message.frame > m.frame);
    assert.ok(later.maps <= Math.floor(later.step / kMapEverySteps) + 2,
      `${later.maps} maps in ${later.step} steps`);
    assert.deepEqual(later.refused, [], 'map messages that break docs/gui-protocol.md');
    await page.screenshot({ path: path.join(kOutput, 'map.png') });

    // A page that connects later, while paused (no new map comes), gets the newest at once.
    await send(page, 'pause');
    const newest = await page.evaluate(async () => {
      await new Promise((r) => setTimeout(r, 1000));  // a map sent as the pause came
      return window.saccadeGui.mapCounts();
    });
    const other = await openPage(browser, server.url.href);
    try {
      await other.waitForFunction(() => window.saccadeGui?.mapsReceived >= 1, null,
        { timeout: kReadyTimeoutMs, polling: 100 });
      const got = await other.evaluate(() => window.saccadeGui.mapCounts());
      assert.equal(got.points, newest.points);
      assert.equal(got.inhibited, newest.inhibited);
      assert.equal(got.message.frame, newest.message.frame);
    } finally {
      await other.close();
    }
    await send(page, 'resume');
  });
});

describe('saccade gui with the humanoid head (--head robots/humanoid.yaml)', () => {
  let browser, server, page;
  const urdf = readUrdf(kHumanoidUrdf);

  before(async () => {
    browser = await chromium.launch({ executablePath: '/usr/bin/chromium', args: kChromiumArgs });
    server = await startSaccade(['gui', '--scene', kScene, '--head', kHumanoidHead, '--port', '0']);
    page = await browser.newPage({ viewport: kViewport });
    page.on('pageerror', (e) => console.log(`page error: ${e.message}`));
    // The joints plot is the page's list of the joints: its legend (one "NAME VALUE" per joint,
    // drawn after the title on its canvas) is recorded as the page draws it.
    await page.addInitScript(() => {
      const fillText = CanvasRenderingContext2D.prototype.fillText;
      let drawing = null;
      CanvasRenderingContext2D.prototype.fillText = function (text, ...rest) {
        if (this.canvas.id === 'plot-joints') {
          if (/^joints\b/.test(text)) drawing = window.jointsPlotLegend = [];
          else drawing?.push(String(text));
        }
        return fillText.call(this, text, ...rest);
      };
    });
    await page.goto(server.url.href);
  });

  after(async () => {
    await page?.close().catch(() => {});
    await browser?.close().catch(() => {});
    await stopSaccade(server);
  });

  test('humanoid: drawn from its URDF, its joints listed, a drag turns the neck, a click fixates', async () => {
    assert.deepEqual([...urdf.joints].sort(), [...kHumanoidJoints].sort(), `${kHumanoidUrdf}: its joints`);
    await waitReady(page);
    await send(page, 'resume');

    // 1. The robot is drawn: every URDF link is a group of the page's 3D scene, with one part
    // (meshes with vertices) per <visual>; nothing of POPEYE. The scene is taken from the page's
    // own three.js module (the same URL: the same module) as the renderer updates it.
    const drawn = await page.evaluate(async (popeyeLinks) => {
      const THREE = await import('/vendor/three/build/three.module.js');
      const update = THREE.Object3D.prototype.updateMatrixWorld;
      let scene = null;
      THREE.Object3D.prototype.updateMatrixWorld = function (force) {
        if (this.isScene) scene = this;
        return update.call(this, force);
      };
      try {
        window.saccadeGui.render();
      } finally {
        THREE.Object3D.prototype.updateMatrixWorld = update;
      }
      if (!scene) throw new Error('the page rendered no scene');
      const g = window.saccadeGui;
      const names = new Set(g.scene.robot.links.map((l) => l.name));
      const links = {};
      const robot = new THREE.Box3();
      for (const group of scene.children.filter((o) => names.has(o.name))) {
        const parts = group.children.map((part) => {
          const meshes = [];
          part.traverse((m) => { if (m.isMesh) meshes.push(m); });
          return meshes.map((m) => ({ vertices: m.geometry.attributes.position?.count ?? 0,
            link: m.userData.link, visible: m.visible }));
        });
        group.updateMatrixWorld(true);
        if (group.children.length) robot.expandByObject(group);
        links[group.name] = { visible: group.visible, parts };
      }
      const popeye = popeyeLinks.filter((n) => scene.getObjectByName(n));
      const strayMeshes = [];
      scene.traverse((m) => {
        const link = m.userData.link;
        if (m.isMesh && link !== undefined && !names.has(link)) strayMeshes.push(link);
      });
      return {
        sceneLinks: [...names], links, popeye, strayMeshes,
        robotCentre: robot.isEmpty() ? null : robot.getCenter(new THREE.Vector3()).toArray(),
        X_WC: g.state.frames.X_WC,
        headJoints: g.scene.head.joints.map((j) => j.name),
        stateJoints: Object.keys(g.state.joints.positions),
        legend: window.jointsPlotLegend ?? null,
      };
    }, kPopeyeLinks);
    assert.deepEqual([...drawn.sceneLinks].sort(), Object.keys(urdf.visuals).sort(), '/api/scene robot.links');
    assert.deepEqual(Object.keys(drawn.links).sort(), Object.keys(urdf.visuals).sort(),
      'the link groups in the page');
    for (const [name, count] of Object.entries(urdf.visuals)) {
      const link = drawn.links[name];
      assert.equal(link.visible, true, `link ${name} is hidden`);
      assert.equal(link.parts.length, count,
        `link ${name}: ${link.parts.length} parts drawn, the URDF has ${count} visuals`);
      for (const meshes of link.parts) {
        assert.ok(meshes.length > 0, `link ${name}: a part without a mesh`);
        for (const m of meshes) {
          assert.ok(m.vertices > 0 && m.visible && m.link === name, `link ${name}: mesh ${JSON.stringify(m)}`);
        }
      }
    }
    assert.deepEqual(drawn.popeye, [], 'POPEYE\'s links in the page');
    assert.deepEqual(drawn.strayMeshes, [], 'robot meshes of links the head does not have');
    // The drawn body is where the head is: its box's centre near the point between the eyes.
    const cyclopean = [0, 1, 2].map((r) => drawn.X_WC[r][3]);
    const offset = Math.hypot(...drawn.robotCentre.map((v, i) => v - cyclopean[i]));
    assert.ok(offset < kRobotCentreToleranceM,
      `the robot's centre [${drawn.robotCentre}] is ${offset.toFixed(3)} m from the eyes' [${cyclopean}]`);
    // The six joints, in the head's order, in the scene, the state and the joints plot's legend.
    assert.deepEqual(drawn.headJoints, kHumanoidJoints, '/api/scene head.joints');
    assert.deepEqual([...drawn.stateJoints].sort(), [...kHumanoidJoints].sort(), 'state joints.positions');
    assert.ok(drawn.legend, 'the joints plot drew no legend');
    const labels = drawn.legend.map((t) => t.slice(0, t.lastIndexOf(' ')));
    assert.deepEqual(labels, kHumanoidJoints, `the joints plot's legend ${JSON.stringify(drawn.legend)}`);
    for (const p of kPopeyeJoints) assert.ok(!labels.includes(p), `POPEYE's joint ${p} in the legend`);

    // 2. Dragging the skull turns the neck's yaw (its joint, head_link's), nothing else: a drag
    // of kHumanoidDragPx to the right, seen from behind the head, turns it right by 10 deg.
    const home = Object.fromEntries(kHumanoidJoints.map((j) => [j, 0]));
    await moveHead(page, home);
    await page.evaluate(() => window.saccadeGui.setView([-0.75, -0.35, 1.55], [0.0, 0.0, 1.2]));
    const watched = ['base_link', 'neck_roll_link', 'head_link', 'left_eye_link', 'left_camera_link',
      'right_camera_link'];
    const placed = (names) => page.evaluate((ns) => Object.fromEntries(
      ns.map((n) => [n, window.saccadeGui.placementOf(n)])), names);
    const before = await placed(watched);
    const p = await page.evaluate(() => window.saccadeGui.screenPointOf('head_link'));
    assert.ok(p.visible, `the skull is hidden in the view (${JSON.stringify(p)})`);
    const x0 = Math.round(p.x), y0 = Math.round(p.y);
    const gain = await page.evaluate(() => window.saccadeGui.dragGainDegPerPx);
    await page.mouse.move(x0, y0);
    await page.mouse.down();
    for (let i = 1; i <= kHumanoidDragPx; i++) {
      await page.mouse.move(x0 + i, y0);
      await page.waitForTimeout(30);
    }
    await page.mouse.up();
    const expected = -gain * kHumanoidDragPx * kDeg;
    let s;
    try {
      s = await waitState(page, (st, { e, tol, settled, names }) => {
        const { positions: q, targets: t } = st.joints;
        return Math.abs(t.neck_yaw - e) < tol && names.every((n) => Math.abs(q[n] - t[n]) < settled);
      }, { e: expected, tol: kHumanoidDragToleranceDeg * kDeg, settled: kSettledDeg * kDeg,
        names: kHumanoidJoints });
    } catch {
      s = await page.evaluate(() => window.saccadeGui.state);
      assert.fail(`neck_yaw not at ${(expected / kDeg).toFixed(1)} deg after the drag: ` +
        `joints ${JSON.stringify(s.joints)}`);
    }
    const yaw = s.joints.positions.neck_yaw;
    for (const j of kHumanoidJoints.filter((n) => n !== 'neck_yaw')) {
      assert.equal(s.joints.targets[j], 0, `the drag moved ${j}'s target`);
      assert.ok(Math.abs(s.joints.positions[j]) < kSettledDeg * kDeg, `${j} at ${s.joints.positions[j]} rad`);
    }
    // The page follows: the base and the neck below the yaw joint stay, the skull, the eyes and
    // the cameras turn by the yaw about the vertical; each placed at the state's frame.
    await page.waitForFunction((step) => window.saccadeGui.state.step > step, s.step, { timeout: kMoveTimeoutMs });
    const moved = await page.evaluate((ns) => ({ frames: window.saccadeGui.state.frames.links,
      placed: Object.fromEntries(ns.map((n) => [n, window.saccadeGui.placementOf(n)])) }), watched);
    for (const n of watched) {
      assert.ok(maxAbsDiff(moved.placed[n], moved.frames[n]) <= kPoseTolerance,
        `${n} placed ${JSON.stringify(moved.placed[n])}, its frame ${JSON.stringify(moved.frames[n])}`);
    }
    for (const n of ['base_link', 'neck_roll_link']) {
      const d = maxAbsDiff(moved.placed[n], before[n]);
      assert.ok(d <= kPoseTolerance, `${n} moved by ${d} with the neck's yaw`);
    }
    for (const n of ['head_link', 'left_eye_link', 'left_camera_link', 'right_camera_link']) {
      const turned = rotationBetweenDeg(before[n], moved.placed[n]);
      assert.ok(Math.abs(turned - Math.abs(yaw) / kDeg) < kYawAngleToleranceDeg,
        `${n} turned by ${turned.toFixed(3)} deg, the neck's yaw is ${(yaw / kDeg).toFixed(3)} deg`);
      // About the vertical: the link's z axis stays where it was.
      assert.ok(Math.abs(moved.placed[n][2][2] - before[n][2][2]) < 1e-6, `${n}: its z axis tilted`);
    }
    const shift = Math.hypot(...[0, 1, 2].map(
      (r) => moved.placed.left_camera_link[r][3] - before.left_camera_link[r][3]));
    assert.ok(shift > 0.01, `the left camera moved by ${shift.toFixed(4)} m with a 10 deg yaw`);

    // 3. Clicking a portrait fixates it: both optical axes (the z columns of the state's camera
    // frames) through the clicked point, every joint within the head's limits.
    await moveHead(page, home);
    await page.evaluate(() => window.saccadeGui.setView([-1.5, -0.7, 2.1], [1.0, 0.0, 1.0]));
    const q = await page.evaluate(() => window.saccadeGui.screenPointOf('astronaut_near'));
    assert.ok(q.visible, `astronaut_near is hidden in the view (${JSON.stringify(q)})`);
    const errorsBefore = await page.evaluate(() => window.saccadeGui.errors.length);
    await page.evaluate(() => { window.saccadeGui.lastClick = null; });
    await page.mouse.click(q.x, q.y);
    await page.waitForFunction(() => window.saccadeGui.lastClick, null, { timeout: 10_000 });
    const click = await page.evaluate(() => window.saccadeGui.lastClick);
    const axisErrors = (st, x) => ['left', 'right'].map((name) => {
      const m = st.frames[name];
      const d = [x[0] - m[0][3], x[1] - m[1][3], x[2] - m[2][3]];
      const cos = (m[0][2] * d[0] + m[1][2] * d[1] + m[2][2] * d[2]) / Math.hypot(...d);
      return Math.acos(Math.min(1, cos)) * 180 / Math.PI;
    });
    try {
      s = await waitState(page, (st, { names, settled }) => {
        const { positions: x, targets: t } = st.joints;
        return names.some((n) => Math.abs(t[n]) > 1e-3) && names.every((n) => Math.abs(x[n] - t[n]) < settled);
      }, { names: kHumanoidJoints, settled: 0.02 * kDeg }, 60_000);
    } catch {
      s = await page.evaluate(() => window.saccadeGui.state);
      const errors = await page.evaluate((n) => window.saccadeGui.errors.slice(n), errorsBefore);
      assert.fail(`not fixated in 60 s: axis errors ${axisErrors(s, click).map((x) => x.toFixed(2))} deg, ` +
        `joints ${JSON.stringify(s.joints)}; errors ${JSON.stringify(errors)}`);
    }
    assert.deepEqual(await page.evaluate((n) => window.saccadeGui.errors.slice(n), errorsBefore), []);
    const errors = axisErrors(s, click);
    console.log(`humanoid fixated [${click.map((v) => v.toFixed(3))}]: axis errors ` +
      `${errors.map((x) => x.toFixed(3))} deg, joints ${JSON.stringify(Object.fromEntries(
        Object.entries(s.joints.positions).map(([k, v]) => [k, +(v / kDeg).toFixed(2)])))} deg`);
    for (const e of errors) assert.ok(e < kHumanoidFixationToleranceDeg, `axis errors ${errors} deg`);
    const limits = await page.evaluate(() => window.saccadeGui.scene.head.joints);
    for (const j of limits) {
      const v = s.joints.positions[j.name];
      assert.ok(v >= j.min && v <= j.max, `${j.name} at ${v} rad, outside [${j.min}, ${j.max}]`);
    }
    assert.equal(s.joints.targets.neck_roll, 0, 'the fixation moved the held neck roll');
  });
});

// The two camera views (live JPEG frames with the server's overlays), the controls that
// command the simulation and reflect its state, and the log of errors and events.

/**
 * One camera's live image: each frame's JPEG decoded once, off the page's main thread
 * (createImageBitmap), and drawn into the view's canvas (a CPU canvas: a GPU one makes the page
 * wait for the GPU process at every drawing); `onImage(name, bitmap)` may draw the same picture
 * elsewhere (the world's image plane) before the bitmap is released. A frame that arrives while
 * one is decoding waits; a newer one replaces it (only the newest is shown). `onDone()` is called
 * once for every frame the view is finished with: shown, failed or replaced while waiting. The
 * canvas is 0 x 0 until the first picture.
 */
export class CameraView {
  constructor(canvas, label, name, onImage, onDone) {
    this.canvas = canvas;
    this.context = canvas.getContext('2d', { willReadFrequently: true });
    this.label = label;
    this.name = name;
    this.onImage = onImage;
    this.onDone = onDone;
    this.decoding = false;
    this.waiting = null;       // [header, blob]
    this.received = 0;         // frames received
    this.shown = 0;            // frames decoded and shown
    this.failed = 0;           // frames that did not decode (not shown)
  }

  frame(header, blob) {
    this.received++;
    if (this.decoding) {
      if (this.waiting) this.onDone?.();  // replaced: never shown
      this.waiting = [header, blob];
      return;
    }
    this.show(header, blob);
  }

  show(header, blob) {
    this.decoding = true;
    createImageBitmap(blob).then(
      (bitmap) => this.decoded(header, bitmap),
      () => this.decoded(header, null));
  }

  // `bitmap`: the frame decoded, or null when it did not (then nothing is shown). Whatever
  // happens in drawing it, the frame is done with and the next waiting frame goes on.
  decoded(header, bitmap) {
    this.decoding = false;
    try {
      if (bitmap) {
        if (this.canvas.width !== bitmap.width || this.canvas.height !== bitmap.height) {
          this.canvas.width = bitmap.width;
          this.canvas.height = bitmap.height;
        }
        this.context.drawImage(bitmap, 0, 0);
        this.shown++;
        this.label.textContent = `${this.name} camera · ${header.width}×${header.height} · frame ${header.frame} · t ${Number(header.time).toFixed(2)} s${cameraControls(header)}`;
        this.onImage?.(this.name, bitmap);
      } else {
        this.failed++;
      }
    } finally {
      bitmap?.close();
      this.onDone?.();
      if (this.waiting) {
        const [next, blob] = this.waiting;
        this.waiting = null;
        this.show(next, blob);
      }
    }
  }
}

/**
 * The camera controls a frame was taken with (its header's exposure_s, gain_db, focus_m), as the
 * label's tail: " · 8.0 ms · 0.0 dB · focus 2.00 m"; an instant's exposure and no focus are left out.
 */
export function cameraControls(header) {
  let text = '';
  if (header.exposure_s > 0) text += ` · ${(header.exposure_s * 1000).toFixed(1)} ms`;
  text += ` · ${Number(header.gain_db).toFixed(1)} dB`;
  if (header.focus_m > 0) text += ` · focus ${header.focus_m.toFixed(2)} m`;
  return text;
}

/** A line in the page's log (errors in red). */
export function log(element, text, level = 'info') {
  const line = document.createElement('div');
  line.className = `log-${level}`;
  line.textContent = `${new Date().toLocaleTimeString()} ${text}`;
  element.prepend(line);
  while (element.childElementCount > 100) element.lastElementChild.remove();
}

/** What the effect switches that only some cameras have do, for their tooltips. */
const kCameraEffects = {
  optics: 'the lens\'s vignetting and depth of field',
  color: 'the colour filter array, demosaicing, white balance and tone curve',
};

/**
 * The controls: effects, perception, pause/resume, step, speed, stop, record, and the image plane's
 * distance. `send(type, fields)` sends a command; `onDistance(d)` moves the image planes; `doc`,
 * the scene document, says which effects exist (`commands.effects`, each camera's `optics` and
 * `color`): a switch that would change no image is disabled, its tooltip says why.
 */
export class Controls {
  constructor(root, send, onDistance, doc) {
    this.root = root;
    const $ = (id) => root.querySelector(`#${id}`);
    this.effects = {
      distortion: $('fx-distortion'), noise: $('fx-noise'), motion_blur: $('fx-blur'),
      optics: $('fx-optics'), color: $('fx-color'),
    };
    for (const [key, box] of Object.entries(this.effects)) {
      box.addEventListener('change', () => send('effects', { [key]: box.checked }));
      if (doc && !doc.commands.effects) {
        box.disabled = true;
        box.parentElement.title = 'the cameras are not simulated';
      }
    }
    for (const [key, what] of Object.entries(kCameraEffects)) {
      const box = this.effects[key];
      const cameras = (doc?.cameras ?? []).filter((c) => c[key]).map((c) => c.name);
      if (box.disabled) continue;
      box.disabled = cameras.length === 0;
      box.parentElement.title = cameras.length === 0
        ? `no camera of this scene has ${what}` : `${what} of ${cameras.join(', ')}`;
    }
    this.perception = $('perception');
    this.perception.addEventListener('change', () => send('perception', { enabled: this.perception.checked }));
    this.pause = $('pause');
    this.pause.addEventListener('click', () => send(this.paused ? 'resume' : 'pause'));
    this.step = $('step');
    this.step.addEventListener('click', () => send('step', { count: 1 }));
    $('stop').addEventListener('click', () => send('stop'));
    this.record = $('record');
    this.recording = false;
    this.record.addEventListener('click', () => send('record', { enabled: !this.recording }));
    this.speed = $('speed');
    this.speed.addEventListener('change', () => send('speed', { factor: Number(this.speed.value) }));
    this.distance = $('plane-distance');
    this.distanceValue = $('plane-distance-value');
    this.distance.addEventListener('input', () => {
      const d = Number(this.distance.value);
      this.distanceValue.textContent = `${d.toFixed(2)} m`;
      onDistance(d);
    });
    this.paused = false;
  }

  /** Shows the server's state in the controls. */
  reflect(state) {
    for (const [key, box] of Object.entries(this.effects)) {
      if (state.effects && key in state.effects) box.checked = !!state.effects[key];
    }
    if ('perception' in state) this.perception.checked = !!state.perception;
    this.paused = !!state.paused;
    this.pause.textContent = this.paused ? 'Resume' : 'Pause';
    this.pause.classList.toggle('active', this.paused);
    this.step.disabled = !this.paused;
    this.recording = !!state.recording;
    this.record.classList.toggle('active', this.recording);
    this.record.textContent = this.recording
      ? `■ Stop recording (${state.recording.megabytes.toFixed(1)} MB)` : '● Record';
    this.record.title = this.recording ? `recording to ${state.recording.file}`
      : 'record every topic to an MCAP file on the server';
    if (Number.isFinite(state.speed) && document.activeElement !== this.speed) {
      const options = [...this.speed.options].map((o) => Number(o.value));
      if (!options.includes(state.speed)) {
        const o = document.createElement('option');
        o.value = String(state.speed);
        o.textContent = `${state.speed}×`;
        this.speed.append(o);
      }
      this.speed.value = String(state.speed);
    }
  }
}

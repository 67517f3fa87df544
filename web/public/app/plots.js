// Small live plots: a canvas each, the last kWindowS seconds of a few named series, with
// their latest values as the legend.

const kWindowS = 20;

export class Plot {
  /** `series`: [{key, label, color}]; `unit` is printed after the title. */
  constructor(canvas, title, series, unit) {
    this.canvas = canvas;
    this.title = title;
    this.series = series;
    this.unit = unit;
    this.samples = [];  // [t_s, {key: value}]
  }

  /** Adds the values at page time `t` (seconds); nulls leave gaps. */
  add(t, values) {
    this.samples.push([t, values]);
    while (this.samples.length && this.samples[0][0] < t - kWindowS) this.samples.shift();
  }

  draw(now) {
    const c = this.canvas;
    const dpr = window.devicePixelRatio || 1;
    const w = c.clientWidth, h = c.clientHeight;
    if (c.width !== Math.round(w * dpr) || c.height !== Math.round(h * dpr)) {
      c.width = Math.round(w * dpr);
      c.height = Math.round(h * dpr);
    }
    // A CPU canvas: a GPU one makes the page wait for the GPU process at each drawing (with a
    // software GPU, for hundreds of ms: bench/gui_page.mjs).
    const ctx = c.getContext('2d', { willReadFrequently: true });
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.clearRect(0, 0, w, h);
    const top = 30, bottom = h - 4, left = 34, right = w - 4;
    // The value range over the window, with a little margin.
    let lo = Infinity, hi = -Infinity;
    for (const [, v] of this.samples) {
      for (const s of this.series) {
        const x = v[s.key];
        if (Number.isFinite(x)) { lo = Math.min(lo, x); hi = Math.max(hi, x); }
      }
    }
    if (!Number.isFinite(lo)) { lo = 0; hi = 1; }
    if (hi - lo < 1e-6) { lo -= 0.5; hi += 0.5; }
    const pad = 0.08 * (hi - lo);
    lo -= pad; hi += pad;
    const X = (t) => right - ((now - t) / kWindowS) * (right - left);
    const Y = (v) => bottom - ((v - lo) / (hi - lo)) * (bottom - top);
    ctx.strokeStyle = '#ccd';
    ctx.lineWidth = 1;
    ctx.strokeRect(left, top, right - left, bottom - top);
    if (lo < 0 && hi > 0) {
      ctx.beginPath(); ctx.moveTo(left, Y(0)); ctx.lineTo(right, Y(0)); ctx.stroke();
    }
    ctx.fillStyle = '#556';
    ctx.font = '10px sans-serif';
    ctx.textBaseline = 'middle';
    ctx.fillText(format(hi), 2, top + 4);
    ctx.fillText(format(lo), 2, bottom - 4);
    // Title and the latest values.
    ctx.textBaseline = 'top';
    ctx.fillStyle = '#223';
    ctx.font = 'bold 11px sans-serif';
    ctx.fillText(this.unit ? `${this.title} (${this.unit})` : this.title, left, 2);
    let x = left;
    const legendY = 15;
    ctx.font = '10px sans-serif';
    const latest = this.samples.at(-1)?.[1] ?? {};
    for (const s of this.series) {
      const text = `${s.label} ${format(latest[s.key])}`;
      ctx.fillStyle = s.color;
      ctx.fillText(text, x, legendY);
      x += ctx.measureText(text).width + 5;
    }
    // The series.
    ctx.save();
    ctx.beginPath(); ctx.rect(left, top, right - left, bottom - top); ctx.clip();
    for (const s of this.series) {
      ctx.strokeStyle = s.color;
      ctx.lineWidth = 1.5;
      ctx.beginPath();
      let drawing = false;
      for (const [t, v] of this.samples) {
        const value = v[s.key];
        if (!Number.isFinite(value)) { drawing = false; continue; }
        if (drawing) ctx.lineTo(X(t), Y(value)); else ctx.moveTo(X(t), Y(value));
        drawing = true;
      }
      ctx.stroke();
    }
    ctx.restore();
  }
}

function format(v) {
  if (!Number.isFinite(v)) return '–';
  const a = Math.abs(v);
  return a >= 10 ? v.toFixed(0) : a >= 1 ? v.toFixed(1) : v.toFixed(2);
}

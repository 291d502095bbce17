// flicker's viewer: every method beside the reference, one frame at a time. Frames arrive as
// RGBE planes (see viewer/encoding.rs) through flickerFrame(); they are decoded to floats here so
// that exposure, pixel values and the SMAPE map work on radiance, not on 8-bit PNGs.
(() => {
  'use strict';
  const C = JSON.parse(document.getElementById('flicker-config').textContent);
  const W = C.width, H = C.height, N = C.frames, NPX = W * H;
  const $ = id => document.getElementById(id);
  const slider = $('frame-slider'), exposure = $('exposure'), playButton = $('play');
  const panels = Array.from(document.querySelectorAll('#panels .panel')).map(fig => ({
    label: fig.dataset.label,
    reference: fig.dataset.reference === 'true',
    view: fig.querySelector('.view'),
    canvas: fig.querySelector('canvas'),
    ctx: fig.querySelector('canvas').getContext('2d'),
    value: fig.querySelector('.value'),
    data: null, // what is shown: {kind: 'rgb' | 'map', values}
  }));
  const state = { frame: 0, shown: -1, exposure: 0, mode: 'image', zoom: 1, fit: 1, tx: 0, ty: 0, playing: false, pointer: null };

  // ---- Frame data: chunks (embedded, or linked scripts), decoded on demand, a few kept.
  const loading = {};
  function chunk(f) {
    if (window.flickerChunks[f]) return Promise.resolve(window.flickerChunks[f]);
    if (!C.linked) return Promise.resolve(null);
    return loading[f] ||= new Promise(resolve => {
      // A <script> works from file:// where fetch() of a sibling file is refused.
      const s = document.createElement('script');
      s.src = C.linked + String(f).padStart(4, '0') + '.js';
      s.onload = () => resolve(window.flickerChunks[f] || null);
      s.onerror = () => resolve(null);
      document.head.appendChild(s);
    });
  }
  async function inflate(b64) {
    const res = await fetch('data:application/octet-stream;base64,' + b64);
    return new Uint8Array(await new Response(res.body.pipeThrough(new DecompressionStream('deflate'))).arrayBuffer());
  }
  const EXP2 = new Float32Array(256).map((_, e) => Math.pow(2, e - 136));
  function rgbeToFloat(b) {
    const out = new Float32Array(3 * NPX);
    for (let i = 0; i < NPX; i++) {
      const e = b[3 * NPX + i];
      if (e === 0) continue;
      const f = EXP2[e];
      out[3 * i] = (b[i] + 0.5) * f;
      out[3 * i + 1] = (b[NPX + i] + 0.5) * f;
      out[3 * i + 2] = (b[2 * NPX + i] + 0.5) * f;
    }
    return out;
  }
  // Motion: planes dx, dy of little-endian i16 in 1/motion_steps pixel (viewer/encoding.rs).
  function motionToFloat(b) {
    const v = new DataView(b.buffer, b.byteOffset, b.byteLength), out = new Float32Array(2 * NPX);
    for (let i = 0; i < 2 * NPX; i++) out[i] = v.getInt16(2 * i, true) / C.motion_steps;
    return out;
  }
  const cache = new Map();
  const CACHE_SIZE = 12 * (panels.length + 1);
  function decoded(f, key) {
    const k = f + '/' + key;
    if (!cache.has(k)) {
      const decode = key.startsWith('flip:') || key.startsWith('jod:') ? b => b : key.startsWith('motion:') ? motionToFloat : rgbeToFloat;
      cache.set(k, chunk(f).then(c => (c && c[key] ? inflate(c[key]) : null)).then(b => b && decode(b)));
      if (cache.size > CACHE_SIZE) cache.delete(cache.keys().next().value);
    }
    return cache.get(k);
  }

  // ---- What each panel shows in each mode.
  function smapeMap(cur, prev) {
    const out = new Float32Array(NPX), eps = C.smape_epsilon;
    for (let i = 0; i < NPX; i++) {
      let s = 0;
      for (let c = 0; c < 3; c++) {
        const a = cur[3 * i + c], b = prev[3 * i + c];
        s += (2 * Math.abs(a - b)) / (Math.abs(a) + Math.abs(b) + eps);
      }
      out[i] = s / 3;
    }
    return out;
  }
  async function content(p, f) {
    if ((state.mode === 'flip' || state.mode === 'jod') && !p.reference) {
      const m = await decoded(f, state.mode + ':' + p.label);
      return m && { kind: 'map', scale: 1, values: Float32Array.from(m, v => v / 255) };
    }
    if (state.mode === 'motion' && !p.reference) {
      const m = await decoded(f, 'motion:' + p.label);
      if (!m) return null;
      let max = 0;
      for (let i = 0; i < NPX; i++) max = Math.max(max, Math.hypot(m[i], m[NPX + i]));
      return { kind: 'motion', max, values: m };
    }
    const cur = await decoded(f, p.label);
    if (state.mode === 'smape' && cur) {
      const prev = f > 0 ? await decoded(f - 1, p.label) : null;
      return prev && { kind: 'map', scale: 2, values: smapeMap(cur, prev) };
    }
    return cur && { kind: 'rgb', values: cur };
  }

  // ---- Painting: exposure and sRGB for radiance, magma for maps.
  const SRGB = new Uint8ClampedArray(4096).map((_, i) => {
    const c = i / 4095;
    return 255 * (c <= 0.0031308 ? 12.92 * c : 1.055 * Math.pow(c, 1 / 2.4) - 0.055) + 0.5;
  });
  function paint(p) {
    const img = p.ctx.createImageData(W, H), px = img.data, d = p.data;
    if (!d) {
      p.ctx.fillStyle = '#555';
      p.ctx.fillRect(0, 0, W, H);
      p.view.classList.add('empty');
      return;
    }
    p.view.classList.remove('empty');
    if (d.kind === 'rgb') {
      const k = Math.pow(2, state.exposure) * 4095;
      for (let i = 0; i < NPX; i++) {
        for (let c = 0; c < 3; c++) px[4 * i + c] = SRGB[Math.min(4095, Math.max(0, d.values[3 * i + c] * k)) | 0];
        px[4 * i + 3] = 255;
      }
    } else if (d.kind === 'motion') {
      // Hue = direction, value = length relative to the panel's longest vector.
      for (let i = 0; i < NPX; i++) {
        const dx = d.values[i], dy = d.values[NPX + i], v = d.max > 0 ? Math.hypot(dx, dy) / d.max : 0;
        const h = ((Math.atan2(dy, dx) / (2 * Math.PI) + 1) % 1) * 6;
        const rgb = [5, 3, 1].map(n => { const k = (n + h) % 6; return v * (1 - Math.max(0, Math.min(k, 4 - k, 1))); });
        for (let c = 0; c < 3; c++) px[4 * i + c] = 255 * rgb[c];
        px[4 * i + 3] = 255;
      }
    } else {
      for (let i = 0; i < NPX; i++) {
        const j = 3 * Math.min(255, Math.max(0, Math.round((255 * d.values[i]) / d.scale)));
        px[4 * i] = C.magma[j];
        px[4 * i + 1] = C.magma[j + 1];
        px[4 * i + 2] = C.magma[j + 2];
        px[4 * i + 3] = 255;
      }
    }
    p.ctx.putImageData(img, 0, 0);
  }

  let token = 0, done = -1, waiters = [];
  async function show(f) {
    f = Math.max(0, Math.min(N - 1, f | 0));
    state.frame = f;
    slider.value = f;
    $('frame-label').textContent = 'frame ' + f + ' / ' + (N - 1);
    moveChartCursors(f);
    const mine = ++token;
    const data = await Promise.all(panels.map(p => content(p, f)));
    if (mine !== token) return; // a later request superseded this one
    panels.forEach((p, i) => { p.data = data[i]; paint(p); });
    state.shown = f;
    done = mine;
    readout();
    if (state.playing) decoded((f + 1) % N, panels[panels.length - 1].label); // warm the next frame
    const w = waiters;
    waiters = [];
    w.forEach(r => r());
  }
  function repaint() { panels.forEach(paint); }

  // ---- Synchronised zoom and pan: one transform for every panel, pixels stay square.
  function applyTransform() {
    const t = 'translate(' + state.tx + 'px,' + state.ty + 'px) scale(' + state.zoom + ')';
    panels.forEach(p => (p.canvas.style.transform = t));
  }
  function fit() {
    const r = panels[0].view.getBoundingClientRect();
    state.fit = state.zoom = r.width / W;
    state.tx = state.ty = 0;
    applyTransform();
  }
  // The image pixel under a client point of panel i (may lie outside the image).
  function pixelAt(i, clientX, clientY) {
    const r = panels[i].view.getBoundingClientRect();
    return [Math.floor((clientX - r.left - state.tx) / state.zoom), Math.floor((clientY - r.top - state.ty) / state.zoom)];
  }
  function valueAt(p, x, y) {
    const d = p.data;
    if (!d || x < 0 || y < 0 || x >= W || y >= H) return null;
    const i = y * W + x;
    if (d.kind === 'rgb') return [d.values[3 * i], d.values[3 * i + 1], d.values[3 * i + 2]];
    return d.kind === 'motion' ? [d.values[i], d.values[NPX + i]] : [d.values[i]];
  }
  function readout() {
    const at = state.pointer;
    $('pixel-label').textContent = at ? 'pixel (' + at[0] + ', ' + at[1] + ')' : 'move the pointer over an image for its pixel values';
    panels.forEach(p => {
      const v = at && valueAt(p, at[0], at[1]);
      p.value.textContent = v ? v.map(x => x.toPrecision(4)).join(' ') : '';
    });
  }
  panels.forEach((p, i) => {
    p.view.addEventListener('wheel', e => {
      e.preventDefault();
      const r = p.view.getBoundingClientRect();
      const [px, py] = [e.clientX - r.left, e.clientY - r.top];
      const zoom = Math.min(state.fit * 64, Math.max(state.fit / 4, state.zoom * Math.exp(-e.deltaY * 0.002)));
      // Keep the point under the cursor fixed: px = tx + zoom * u before and after.
      state.tx = px - ((px - state.tx) * zoom) / state.zoom;
      state.ty = py - ((py - state.ty) * zoom) / state.zoom;
      state.zoom = zoom;
      applyTransform();
    }, { passive: false });
    let drag = null;
    p.view.addEventListener('pointerdown', e => { drag = [e.clientX, e.clientY]; try { p.view.setPointerCapture(e.pointerId); } catch (_) { /* synthetic events have no pointer */ } });
    p.view.addEventListener('pointerup', () => (drag = null));
    p.view.addEventListener('pointermove', e => {
      if (drag) {
        state.tx += e.clientX - drag[0];
        state.ty += e.clientY - drag[1];
        drag = [e.clientX, e.clientY];
        applyTransform();
      }
      state.pointer = pixelAt(i, e.clientX, e.clientY);
      readout();
    });
    p.view.addEventListener('dblclick', fit);
  });

  // ---- Controls.
  slider.addEventListener('input', () => show(+slider.value));
  exposure.addEventListener('input', () => {
    state.exposure = +exposure.value;
    $('exposure-label').textContent = (state.exposure > 0 ? '+' : '') + state.exposure + ' EV';
    repaint();
  });
  document.querySelectorAll('#viewer .modes button').forEach(b => b.addEventListener('click', () => {
    state.mode = b.dataset.mode;
    document.querySelectorAll('#viewer .modes button').forEach(o => o.classList.toggle('on', o === b));
    show(state.frame);
  }));
  let timer = null;
  function play(on) {
    state.playing = on;
    playButton.textContent = on ? 'pause' : 'play';
    clearInterval(timer);
    // One step per frame period; a frame still decoding is not skipped, the next tick waits.
    if (on) timer = setInterval(() => { if (done === token) show((state.frame + 1) % N); }, 1000 / C.fps);
  }
  playButton.addEventListener('click', () => play(!state.playing));
  $('fit').addEventListener('click', fit);
  document.addEventListener('keydown', e => {
    // Controls handle their own keys (a focused slider already steps, a button already clicks).
    if (['INPUT', 'BUTTON', 'SELECT', 'TEXTAREA'].includes(e.target.tagName)) return;
    if (e.key === ' ') { e.preventDefault(); play(!state.playing); }
    if (e.key === 'ArrowRight') show(state.frame + 1);
    if (e.key === 'ArrowLeft') show(state.frame - 1);
  });

  // ---- Charts: a cursor at the viewer's frame on every chart drawn against frame.
  function moveChartCursors(f) {
    document.querySelectorAll('.chart[data-f1]').forEach(c => {
      const d = c.dataset, x = +d.x0 + ((f - d.f0) / (d.f1 - d.f0)) * (d.x1 - d.x0);
      c.querySelector('.cursor').style.left = (100 * x) / d.w + '%';
    });
  }

  window.flickerViewer = {
    state, labels: panels.map(p => p.label), show, pixelAt, valueAt: (i, x, y) => valueAt(panels[i], x, y),
    canvas: i => panels[i].canvas, view: i => panels[i].view,
    // Resolves once the requested frame is on screen.
    whenShown: () => (done === token ? Promise.resolve() : new Promise(r => waiters.push(r))),
  };
  fit();
  // #frame=N in the address, else the frame the report chose (the first event's, or 0).
  const start = /frame=(\d+)/.exec(location.hash);
  show(start ? +start[1] : C.start);
})();

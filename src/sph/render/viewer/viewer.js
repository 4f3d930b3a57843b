// The player of `sph view`: plays a run (or the runs of a compare directory side by side) from
// the data sph inlined in the page. Plain JavaScript on a Canvas 2D, no libraries: the page must
// work offline, from file://, and in browsers without WebGL (headless, remote desktops).
//
// Data (the JSON in #sph-data, written by src/sph/render/viewer.cpp):
//   dimension, box {lo, hi} (the container), obstacles [{lo, hi}] (solid boxes at rest; z = 0 in
//   2D), qbox {lo, hi} (what positions are quantized over),
//   radius (particle radius, m), colors [{name, label, scalar, lo, hi, lut (base64, 256 RGB)}],
//   defaultColor, notes [text], runs [{label, rgb?, frames [{t, n, pos, f {name: base64}, rgb?,
//   poses?}]}].
//   poses (only when an obstacle moves): per obstacle [r00, r01, r02, r10, r11, r12, r20, r21,
//   r22, cx, cy, cz, tx, ty, tz], its placement at the frame's time: the point p of the box at
//   rest is at c + t + R (p - c).
//   pos: n * dimension uint16 (little endian) over qbox; scalar fields: one byte per particle,
//   0..254 over [lo, hi] and 255 for "no value"; rgb: 3 bytes per particle (per run when the
//   particles keep their index in every frame, else per frame).
'use strict';
(function () {
  const DATA = JSON.parse(document.getElementById('sph-data').textContent);
  const DIM = DATA.dimension;
  const RUNS = DATA.runs;
  const FRAME_COUNT = Math.max(...RUNS.map((r) => r.frames.length));
  const $ = (id) => document.getElementById(id);

  // ---- decoding (lazy: a frame's arrays are decoded the first time it is drawn) -------------
  function bytes(b64) {
    const bin = atob(b64);
    const out = new Uint8Array(bin.length);
    for (let i = 0; i < bin.length; i++) out[i] = bin.charCodeAt(i);
    return out;
  }
  const LITTLE_ENDIAN = new Uint8Array(new Uint16Array([1]).buffer)[0] === 1;
  function uint16(b64) {
    const b = bytes(b64);
    if (!LITTLE_ENDIAN) for (let i = 0; i + 1 < b.length; i += 2) { const t = b[i]; b[i] = b[i + 1]; b[i + 1] = t; }
    return new Uint16Array(b.buffer, 0, b.length >> 1);
  }
  const decoded = new Map();  // "run/frame/what" -> typed array
  function cached(key, make) {
    let v = decoded.get(key);
    if (v === undefined) { v = make(); decoded.set(key, v); }
    return v;
  }
  const colorInfo = new Map(DATA.colors.map((c) => [c.name, c]));
  for (const c of DATA.colors) if (c.scalar) c.lutBytes = bytes(c.lut);

  // ---- state -------------------------------------------------------------------------------
  const lo = DATA.qbox.lo, hi = DATA.qbox.hi;
  const boxLo = DATA.box.lo, boxHi = DATA.box.hi;
  const center = [0, 1, 2].map((k) => 0.5 * (boxLo[k] + boxHi[k]));
  const FOV = 35 * Math.PI / 180;
  const state = {
    frame: 0,
    playing: false,
    fps: 25,
    loop: true,
    color: colorInfo.has(DATA.defaultColor) ? DATA.defaultColor : DATA.colors[0].name,
    cam: null,  // set by resetCamera()
  };
  // For scripts that drive the page (tests): what is shown and how many times it was drawn.
  const api = { state, renders: 0, frameCount: FRAME_COUNT, panels: RUNS.length };
  window.sphView = api;

  // ---- layout: one panel per run, in the grid that makes the panels largest -----------------
  const panelsEl = $('panels');
  const panels = RUNS.map((run, i) => {
    const div = document.createElement('div');
    div.className = 'panel';
    const canvas = document.createElement('canvas');
    canvas.setAttribute('aria-label', run.label || 'particles');
    const cap = document.createElement('div');
    cap.className = 'caption';
    cap.textContent = RUNS.length > 1 ? run.label : '';
    div.append(canvas, cap);
    panelsEl.append(div);
    return { run, index: i, div, canvas, ctx: canvas.getContext('2d'), w: 1, h: 1 };
  });

  function boxAspect() {
    const w = boxHi[0] - boxLo[0], h = boxHi[1] - boxLo[1];
    if (DIM === 2) return w / h;
    return (w + 0.6 * (boxHi[2] - boxLo[2])) / (h + 0.4 * (boxHi[2] - boxLo[2]));
  }
  function layout() {
    const W = panelsEl.clientWidth - 28, H = panelsEl.clientHeight - 12;
    const n = panels.length, a = boxAspect();
    let best = 1, bestScale = -1;
    for (let cols = 1; cols <= n; cols++) {
      const rows = Math.ceil(n / cols);
      const pw = (W - 8 * (cols - 1)) / cols, ph = (H - 8 * (rows - 1)) / rows;
      const s = Math.min(pw / a, ph);
      if (s > bestScale + 1e-9) { bestScale = s; best = cols; }
    }
    panelsEl.style.gridTemplateColumns = `repeat(${best}, minmax(0, 1fr))`;
    panelsEl.style.gridTemplateRows = `repeat(${Math.ceil(n / best)}, minmax(0, 1fr))`;
    const dpr = window.devicePixelRatio || 1;
    for (const p of panels) {
      const r = p.div.getBoundingClientRect();
      p.w = Math.max(1, Math.round(r.width * dpr));
      p.h = Math.max(1, Math.round(r.height * dpr));
      if (p.canvas.width !== p.w || p.canvas.height !== p.h) { p.canvas.width = p.w; p.canvas.height = p.h; }
    }
  }

  // ---- camera -------------------------------------------------------------------------------
  // 3D: orbit about `target` at distance `dist` (yaw about the world y axis, pitch above the
  // horizon); perspective or orthographic with the same scale at the target. 2D: pan and zoom.
  function resetCamera() {
    state.cam = { yaw: -0.6, pitch: 0.42, dist: 1, target: center.slice(), zoom: 1, pan: [0, 0] };
    if (DIM === 3) state.cam.dist = fitDistance();
    requestRender();
  }
  function basis(cam) {
    const cp = Math.cos(cam.pitch), sp = Math.sin(cam.pitch), cy = Math.cos(cam.yaw), sy = Math.sin(cam.yaw);
    const back = [cp * sy, sp, cp * cy];  // from target towards the eye
    const right = [cy, 0, -sy];
    const up = [-sp * sy, cp, -sp * cy];
    const eye = [0, 1, 2].map((k) => cam.target[k] + cam.dist * back[k]);
    return { back, right, up, eye };
  }
  function focal(p) { return Math.min(p.w, p.h) / (2 * Math.tan(FOV / 2)); }
  // The distance at which the container fills a panel with a margin, for the current angles.
  function fitDistance() {
    const p = panels[0];
    const b = basis({ ...state.cam, dist: 0 });
    let xmin = Infinity, xmax = -Infinity, ymin = Infinity, ymax = -Infinity, rad = 0;
    for (let c = 0; c < 8; c++) {
      const q = [c & 1 ? boxHi[0] : boxLo[0], c & 2 ? boxHi[1] : boxLo[1], c & 4 ? boxHi[2] : boxLo[2]];
      const d = [0, 1, 2].map((k) => q[k] - center[k]);
      const x = d[0] * b.right[0] + d[2] * b.right[2];
      const y = d[0] * b.up[0] + d[1] * b.up[1] + d[2] * b.up[2];
      xmin = Math.min(xmin, x); xmax = Math.max(xmax, x); ymin = Math.min(ymin, y); ymax = Math.max(ymax, y);
      rad = Math.max(rad, Math.hypot(d[0], d[1], d[2]));
    }
    const f = focal(p);
    const scale = 0.86 * Math.min(p.w / (xmax - xmin), p.h / (ymax - ymin));
    let dist = Math.max(f / scale, 1.2 * rad);
    // In perspective the near corners come out larger: back off until every corner fits.
    if ($('perspective').checked) {
      for (let it = 0; it < 40; it++) {
        const e = [0, 1, 2].map((k) => center[k] + dist * b.back[k]);
        let fits = true;
        for (let c = 0; c < 8 && fits; c++) {
          const q = [c & 1 ? boxHi[0] : boxLo[0], c & 2 ? boxHi[1] : boxLo[1], c & 4 ? boxHi[2] : boxLo[2]];
          const d = [0, 1, 2].map((k) => q[k] - e[k]);
          const zv = -(d[0] * b.back[0] + d[1] * b.back[1] + d[2] * b.back[2]);
          const x = f * (d[0] * b.right[0] + d[2] * b.right[2]) / zv;
          const y = f * (d[0] * b.up[0] + d[1] * b.up[1] + d[2] * b.up[2]) / zv;
          fits = zv > 0 && Math.abs(x) < 0.46 * p.w && Math.abs(y) < 0.46 * p.h;
        }
        if (fits) break;
        dist *= 1.04;
      }
    }
    return dist;
  }

  // ---- sprites: one pre-rendered disc per color bucket, drawn scaled with drawImage ----------
  const SCALAR_BUCKETS = 128, RGB_LEVELS = 12, NAN_COLOR = [150, 150, 150];
  let sprites = null;  // {key, canvas, size, cols}
  function spriteColors() {
    const c = colorInfo.get(state.color);
    const list = [];
    if (c.scalar) {
      for (let i = 0; i < SCALAR_BUCKETS; i++) {
        const k = 3 * Math.round((i + 0.5) / SCALAR_BUCKETS * 255 - 0.5);
        list.push([c.lutBytes[k], c.lutBytes[k + 1], c.lutBytes[k + 2]]);
      }
      list.push(NAN_COLOR);
    } else {
      for (let r = 0; r < RGB_LEVELS; r++)
        for (let g = 0; g < RGB_LEVELS; g++)
          for (let b = 0; b < RGB_LEVELS; b++)
            list.push([r, g, b].map((v) => Math.round(v * 255 / (RGB_LEVELS - 1))));
    }
    return list;
  }
  function spriteSize(px) {
    for (const s of [8, 12, 16, 24, 32, 48, 64, 96, 128]) if (s >= px) return s;
    return 128;
  }
  function getSprites(size) {
    const key = `${state.color}/${size}`;
    if (sprites && sprites.key === key) return sprites;
    const colors = spriteColors();
    const cols = Math.ceil(Math.sqrt(colors.length));
    const canvas = document.createElement('canvas');
    canvas.width = cols * size;
    canvas.height = Math.ceil(colors.length / cols) * size;
    const ctx = canvas.getContext('2d');
    const img = ctx.createImageData(canvas.width, canvas.height);
    // Light from the upper left and in front; the flat 2D discs only darken at the rim.
    const L = [-0.45, 0.55, 0.70], Ln = Math.hypot(...L);
    const H = [L[0] / Ln, L[1] / Ln, L[2] / Ln + 1], Hn = Math.hypot(...H);
    const R = size / 2;
    const shade = new Float32Array(size * size), spec = new Float32Array(size * size), alpha = new Float32Array(size * size);
    for (let y = 0; y < size; y++)
      for (let x = 0; x < size; x++) {
        const u = (x + 0.5 - R) / R, v = (y + 0.5 - R) / R, r2 = u * u + v * v, r = Math.sqrt(r2);
        const i = y * size + x;
        alpha[i] = Math.min(1, Math.max(0, (1 - r) * R + 0.5));
        if (DIM === 3) {
          const nz = Math.sqrt(Math.max(0, 1 - r2));
          const d = Math.max(0, (u * L[0] - v * L[1] + nz * L[2]) / Ln);
          shade[i] = 0.30 + 0.80 * d;
          spec[i] = 0.35 * Math.pow(Math.max(0, (u * H[0] - v * H[1] + nz * H[2]) / Hn), 32);
        } else {
          shade[i] = r > 0.78 ? 0.78 : 1;
          spec[i] = 0;
        }
      }
    colors.forEach((c, k) => {
      const ox = (k % cols) * size, oy = Math.floor(k / cols) * size;
      for (let y = 0; y < size; y++)
        for (let x = 0; x < size; x++) {
          const i = y * size + x, o = 4 * ((oy + y) * canvas.width + ox + x);
          for (let ch = 0; ch < 3; ch++) img.data[o + ch] = Math.min(255, c[ch] * shade[i] + 255 * spec[i]);
          img.data[o + 3] = 255 * alpha[i];
        }
    });
    ctx.putImageData(img, 0, 0);
    sprites = { key, canvas, size, cols, count: colors.length };
    return sprites;
  }

  // ---- per-frame arrays ----------------------------------------------------------------------
  function frameOf(run, f) { return run.frames[Math.min(f, run.frames.length - 1)]; }
  // The sprite index of every particle of a frame for the current color field.
  function buckets(ri, fi) {
    const run = RUNS[ri], fr = frameOf(run, fi), n = fr.n;
    const c = colorInfo.get(state.color);
    return cached(`${ri}/${fi}/b/${state.color}`, () => {
      const out = new Uint16Array(n);
      if (c.scalar) {
        const q = cached(`${ri}/${fi}/f/${c.name}`, () => bytes(fr.f[c.name]));
        for (let i = 0; i < n; i++) out[i] = q[i] === 255 ? SCALAR_BUCKETS : Math.min(SCALAR_BUCKETS - 1, (q[i] * SCALAR_BUCKETS / 255) | 0);
      } else {
        const rgb = fr.rgb ? cached(`${ri}/${fi}/rgb`, () => bytes(fr.rgb)) : cached(`${ri}/rgb`, () => bytes(run.rgb));
        const L = RGB_LEVELS - 1;
        for (let i = 0; i < n; i++) {
          const r = Math.round(rgb[3 * i] * L / 255), g = Math.round(rgb[3 * i + 1] * L / 255), b = Math.round(rgb[3 * i + 2] * L / 255);
          out[i] = (r * RGB_LEVELS + g) * RGB_LEVELS + b;
        }
      }
      return out;
    });
  }
  function positions(ri, fi) {
    const fr = frameOf(RUNS[ri], fi);
    return cached(`${ri}/${fi}/pos`, () => uint16(fr.pos));
  }

  // ---- drawing -------------------------------------------------------------------------------
  const BG = '#f7f8fa';
  let sx = new Float32Array(0), sy = new Float32Array(0), sr = new Float32Array(0), sz = new Float32Array(0);
  let order = new Uint32Array(0), keys = new Uint16Array(0);
  const DEPTH_BINS = 4096;
  const binCount = new Uint32Array(DEPTH_BINS + 1);
  let hid = new Uint8Array(0);  // 1 where a particle is behind (or inside) an obstacle, 3D
  function ensure(n) {
    if (sx.length >= n) return;
    const m = Math.max(n, 2 * sx.length);
    sx = new Float32Array(m); sy = new Float32Array(m); sr = new Float32Array(m); sz = new Float32Array(m);
    order = new Uint32Array(m); keys = new Uint16Array(m); hid = new Uint8Array(m);
  }
  const dq = [0, 1, 2].map((k) => (hi[k] - lo[k]) / 65535);

  // World -> pixel for the current camera and panel; returns [x, y, depth, pixels per metre].
  function projector(p) {
    const cam = state.cam;
    if (DIM === 2) {
      const s = 0.92 * Math.min(p.w / (boxHi[0] - boxLo[0]), p.h / (boxHi[1] - boxLo[1])) * cam.zoom;
      const cx = p.w / 2, cy = p.h / 2, ox = center[0] + cam.pan[0], oy = center[1] + cam.pan[1];
      return { s, fn: (x, y) => [cx + (x - ox) * s, cy - (y - oy) * s, 0, s] };
    }
    const b = basis(cam), f = focal(p), persp = $('perspective').checked;
    const cx = p.w / 2, cy = p.h / 2;
    return {
      s: f / cam.dist,
      fn: (x, y, z) => {
        const dx = x - b.eye[0], dy = y - b.eye[1], dz = z - b.eye[2];
        const xv = dx * b.right[0] + dz * b.right[2];
        const yv = dx * b.up[0] + dy * b.up[1] + dz * b.up[2];
        const zv = -(dx * b.back[0] + dy * b.back[1] + dz * b.back[2]);
        const s = persp ? f / zv : f / cam.dist;
        return [cx + xv * s, cy - yv * s, zv, s];
      },
    };
  }

  function boxEdges() {
    if (DIM === 2) return [[[boxLo[0], boxLo[1], 0], [boxHi[0], boxLo[1], 0]], [[boxHi[0], boxLo[1], 0], [boxHi[0], boxHi[1], 0]],
      [[boxHi[0], boxHi[1], 0], [boxLo[0], boxHi[1], 0]], [[boxLo[0], boxHi[1], 0], [boxLo[0], boxLo[1], 0]]];
    const c = (i) => [i & 1 ? boxHi[0] : boxLo[0], i & 2 ? boxHi[1] : boxLo[1], i & 4 ? boxHi[2] : boxLo[2]];
    const edges = [];
    for (let i = 0; i < 8; i++) for (const bit of [1, 2, 4]) if (!(i & bit)) edges.push([c(i), c(i | bit)]);
    return edges;
  }
  const EDGES = boxEdges();

  function drawEdges(ctx, proj, which, dpr) {
    // Edges behind the box center are drawn under the particles, the others over them (faint).
    const cz = proj.fn(center[0], center[1], center[2])[2];
    ctx.lineWidth = Math.max(1, 1.25 * dpr);
    ctx.strokeStyle = which === 'back' ? 'rgba(70, 78, 90, 0.75)' : 'rgba(70, 78, 90, 0.45)';
    ctx.beginPath();
    for (const [a, b] of EDGES) {
      const pa = proj.fn(...a), pb = proj.fn(...b);
      const back = DIM === 2 || 0.5 * (pa[2] + pb[2]) >= cz;
      if ((which === 'back') !== back) continue;
      if (pa[2] <= 0 && DIM === 3 && $('perspective').checked) continue;
      ctx.moveTo(pa[0], pa[1]);
      ctx.lineTo(pb[0], pb[1]);
    }
    ctx.stroke();
  }

  // ---- obstacles: solid boxes, as sph render draws them (src/sph/render/particles.h) ----------
  // 2D: gray rectangles with a darker outline, over the particles. 3D: each box's faces turned to
  // the camera, flat-shaded by facing, with their edges; particles whose center is behind (or
  // inside) an obstacle are drawn before the faces, the others after them.
  const OBSTACLES = DATA.obstacles || [];
  const SOLID_RGB = [196, 196, 196], SOLID_EDGE = 'rgb(72, 72, 72)';
  const FACE_LIGHT = (() => {  // camera space (right, up, back): mostly from above
    const l = [-0.35, 0.85, 0.4], n = Math.hypot(...l);
    return l.map((v) => v / n);
  })();
  function solidRgb(shade) { return `rgb(${SOLID_RGB.map((c) => Math.round(c * shade)).join(', ')})`; }

  // The obstacles of a frame as drawn: each box at rest with its placement in that frame (the
  // frame's poses) or at rest. R is null for an upright box (then the point p is at p + t).
  // A polygon or mesh obstacle also has its vertices `v` (and 3D `f`, triangles; `inv`: the solid
  // is outside it): drawn as sph render draws it (2D polygons filled, 3D triangles flat-shaded);
  // whether a particle is behind it is judged by its bounds.
  const AT_REST = OBSTACLES.map((o) => ({ lo: o.lo, hi: o.hi, R: null, c: [0, 0, 0], t: [0, 0, 0], v: o.v, f: o.f,
    inv: o.inv }));
  function solidsOf(ri, fi) {
    const fr = frameOf(RUNS[ri], fi);
    if (!fr.poses) return AT_REST;
    return cached(`${ri}/${fi}/solids`, () => OBSTACLES.map((o, k) => {
      const pose = fr.poses[k];
      if (!pose) return AT_REST[k];
      const R = pose.slice(0, 9);
      const upright = R.every((v, j) => v === (j % 4 === 0 ? 1 : 0));
      return { lo: o.lo, hi: o.hi, R: upright ? null : R, c: pose.slice(9, 12), t: pose.slice(12, 15), v: o.v, f: o.f,
        inv: o.inv };
    }));
  }
  // Where the point p of the box at rest is drawn.
  function place(o, p) {
    if (!o.R) return [p[0] + o.t[0], p[1] + o.t[1], p[2] + o.t[2]];
    const R = o.R, d0 = p[0] - o.c[0], d1 = p[1] - o.c[1], d2 = p[2] - o.c[2];
    return [0, 1, 2].map((a) => o.c[a] + o.t[a] + R[3 * a] * d0 + R[3 * a + 1] * d1 + R[3 * a + 2] * d2);
  }

  // True if the segment from the world point towards the eye (orthographic: the ray towards the
  // viewer) meets an obstacle, the point itself included (slab test, in the box's own frame).
  function hiddenBySolid(x, y, z, b, persp, solids) {
    const dw = persp ? [b.eye[0] - x, b.eye[1] - y, b.eye[2] - z] : b.back;
    for (const o of solids) {
      let p = [x - o.t[0], y - o.t[1], z - o.t[2]], d = dw;
      if (o.R) {  // back to the box at rest: c + R^T (x - c - t), and R^T d
        const R = o.R, q0 = p[0] - o.c[0], q1 = p[1] - o.c[1], q2 = p[2] - o.c[2];
        p = [0, 1, 2].map((a) => o.c[a] + R[a] * q0 + R[3 + a] * q1 + R[6 + a] * q2);
        d = [0, 1, 2].map((a) => R[a] * dw[0] + R[3 + a] * dw[1] + R[6 + a] * dw[2]);
      }
      let t0 = 0, t1 = persp ? 1 : Infinity;
      for (let k = 0; k < 3 && t0 <= t1; k++) {
        if (Math.abs(d[k]) < 1e-12) {
          if (p[k] < o.lo[k] || p[k] > o.hi[k]) t0 = Infinity;
          continue;
        }
        let ta = (o.lo[k] - p[k]) / d[k], tb = (o.hi[k] - p[k]) / d[k];
        if (ta > tb) { const t = ta; ta = tb; tb = t; }
        if (ta > t0) t0 = ta;
        if (tb < t1) t1 = tb;
      }
      if (t0 <= t1) return true;
    }
    return false;
  }

  function polygon(ctx, pts) {
    ctx.beginPath();
    ctx.moveTo(pts[0][0], pts[0][1]);
    for (let k = 1; k < pts.length; k++) ctx.lineTo(pts[k][0], pts[k][1]);
    ctx.closePath();
  }

  function drawSolids(ctx, proj, dpr, solids) {
    if (!solids.length) return;
    ctx.lineWidth = Math.max(1, 1.25 * dpr);
    ctx.lineJoin = 'round';
    ctx.strokeStyle = SOLID_EDGE;
    if (DIM === 2) {
      ctx.fillStyle = solidRgb(1);
      const e = ctx.lineWidth / 2;  // the outline inside the box, as sph render draws it
      for (const o of solids) {
        if (o.v) {  // a polygon: filled (unless the fluid is inside it) and outlined
          polygon(ctx, o.v.map((p) => { const w = place(o, [p[0], p[1], 0]); return proj.fn(w[0], w[1], 0); }));
          if (!o.inv) ctx.fill();
          ctx.stroke();
          continue;
        }
        if (!o.R) {
          const a = proj.fn(o.lo[0] + o.t[0], o.lo[1] + o.t[1], 0), c = proj.fn(o.hi[0] + o.t[0], o.hi[1] + o.t[1], 0);
          const x = Math.min(a[0], c[0]), y = Math.min(a[1], c[1]), w = Math.abs(c[0] - a[0]), h = Math.abs(c[1] - a[1]);
          ctx.fillRect(x, y, w, h);
          if (w > 2 * e && h > 2 * e) ctx.strokeRect(x + e, y + e, w - 2 * e, h - 2 * e);
          continue;
        }
        // A turned box: the quadrilateral through its placed corners, outlined inside (its box
        // shrunk by half the line width before it is placed).
        const corners = (m) => [[o.lo[0] + m, o.lo[1] + m], [o.hi[0] - m, o.lo[1] + m], [o.hi[0] - m, o.hi[1] - m],
          [o.lo[0] + m, o.hi[1] - m]].map(([x, y]) => { const w = place(o, [x, y, 0]); return proj.fn(w[0], w[1], 0); });
        polygon(ctx, corners(0));
        ctx.fill();
        const m = e / proj.s;
        if (o.hi[0] - o.lo[0] > 2 * m && o.hi[1] - o.lo[1] > 2 * m) {
          polygon(ctx, corners(m));
          ctx.stroke();
        }
      }
      return;
    }
    const b = basis(state.cam), persp = $('perspective').checked;
    const boxes = solids.map((o) => {
      const c = place(o, [0, 1, 2].map((k) => 0.5 * (o.lo[k] + o.hi[k])));
      return { o, depth: proj.fn(c[0], c[1], c[2])[2] };
    });
    boxes.sort((u, v) => v.depth - u.depth);  // far to near
    for (const { o } of boxes) {
      if (o.f) {  // a mesh: its triangles turned to the camera (away when inverted), far to near
        const tris = [];
        for (const t of o.f) {
          const w = t.map((k) => place(o, o.v[k]));
          const e1 = [0, 1, 2].map((k) => w[1][k] - w[0][k]), e2 = [0, 1, 2].map((k) => w[2][k] - w[0][k]);
          let n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
          const len = Math.hypot(...n) * (o.inv ? -1 : 1);
          if (!len) continue;
          n = n.map((x) => x / len);
          const facing = persp ? n[0] * (b.eye[0] - w[0][0]) + n[1] * (b.eye[1] - w[0][1]) + n[2] * (b.eye[2] - w[0][2])
                               : n[0] * b.back[0] + n[1] * b.back[1] + n[2] * b.back[2];
          if (!(facing > 1e-9)) continue;
          const pts = w.map((q) => proj.fn(q[0], q[1], q[2]));
          if (persp && pts.some((q) => q[2] <= 0)) continue;
          const nc = [b.right, b.up, b.back].map((e) => n[0] * e[0] + n[1] * e[1] + n[2] * e[2]);
          const shade = 0.55 + 0.45 * Math.max(0, nc[0] * FACE_LIGHT[0] + nc[1] * FACE_LIGHT[1] + nc[2] * FACE_LIGHT[2]);
          tris.push({ pts, shade, depth: (pts[0][2] + pts[1][2] + pts[2][2]) / 3 });
        }
        tris.sort((u, v) => v.depth - u.depth);
        for (const t of tris) {
          ctx.fillStyle = ctx.strokeStyle = solidRgb(t.shade);  // (stroked in its own color: no seams)
          polygon(ctx, t.pts);
          ctx.fill();
          ctx.stroke();
        }
        ctx.strokeStyle = SOLID_EDGE;
        continue;
      }
      for (let a = 0; a < 3; a++) {
        const axis = o.R ? [o.R[a], o.R[3 + a], o.R[6 + a]] : [0, 1, 2].map((k) => (k === a ? 1 : 0));
        for (const side of [0, 1]) {
          const sign = side ? 1 : -1, n = axis.map((v) => sign * v);
          const mid = [0, 1, 2].map((k) => 0.5 * (o.lo[k] + o.hi[k]));
          mid[a] = side ? o.hi[a] : o.lo[a];
          const at = place(o, mid);  // the face's center
          // Turned to the camera: towards the eye (perspective) or the viewer (orthographic).
          const facing = persp ? n[0] * (b.eye[0] - at[0]) + n[1] * (b.eye[1] - at[1]) + n[2] * (b.eye[2] - at[2])
                               : n[0] * b.back[0] + n[1] * b.back[1] + n[2] * b.back[2];
          if (!(facing > 1e-9)) continue;
          const u = (a + 1) % 3, v = (a + 2) % 3, pts = [];
          for (const [ku, kv] of [[0, 0], [1, 0], [1, 1], [0, 1]]) {
            const w = [0, 0, 0];
            w[a] = mid[a]; w[u] = ku ? o.hi[u] : o.lo[u]; w[v] = kv ? o.hi[v] : o.lo[v];
            const q = place(o, w);
            pts.push(proj.fn(q[0], q[1], q[2]));
          }
          if (persp && pts.some((q) => q[2] <= 0)) continue;  // reaches behind the eye
          const nc = [b.right, b.up, b.back].map((e) => n[0] * e[0] + n[1] * e[1] + n[2] * e[2]);  // camera space
          const shade = 0.55 + 0.45 * Math.max(0, nc[0] * FACE_LIGHT[0] + nc[1] * FACE_LIGHT[1] + nc[2] * FACE_LIGHT[2]);
          ctx.fillStyle = solidRgb(shade);
          polygon(ctx, pts);
          ctx.fill();
          ctx.stroke();
        }
      }
    }
  }

  function drawAxes(ctx, p, dpr) {
    if (DIM !== 3) return;
    const b = basis(state.cam), L = 22 * dpr, ox = 34 * dpr, oy = p.h - 30 * dpr;
    const axes = [[[1, 0, 0], '#d0473c', 'x'], [[0, 1, 0], '#3a9a4a', 'y'], [[0, 0, 1], '#3567c8', 'z']];
    ctx.lineWidth = 2 * dpr;
    ctx.font = `${11 * dpr}px system-ui, sans-serif`;
    ctx.textAlign = 'center';
    ctx.textBaseline = 'middle';
    for (const [v, col, name] of axes) {
      const x = v[0] * b.right[0] + v[2] * b.right[2], y = v[0] * b.up[0] + v[1] * b.up[1] + v[2] * b.up[2];
      ctx.strokeStyle = col;
      ctx.fillStyle = col;
      ctx.beginPath();
      ctx.moveTo(ox, oy);
      ctx.lineTo(ox + x * L, oy - y * L);
      ctx.stroke();
      ctx.fillText(name, ox + x * (L + 8 * dpr), oy - y * (L + 8 * dpr));
    }
  }

  function drawPanel(p) {
    const ctx = p.ctx, dpr = window.devicePixelRatio || 1;
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.globalAlpha = 1;
    ctx.fillStyle = BG;
    ctx.fillRect(0, 0, p.w, p.h);
    const fi = Math.min(state.frame, p.run.frames.length - 1);
    const fr = p.run.frames[fi], n = fr.n;
    const pos = positions(p.index, fi), bk = buckets(p.index, fi);
    const proj = projector(p);
    ensure(n);
    const persp = DIM === 3 && $('perspective').checked;
    const occluding = DIM === 3 && OBSTACLES.length > 0, b3 = occluding ? basis(state.cam) : null;
    const solids = solidsOf(p.index, fi);  // where the obstacles are in this frame
    let zmin = Infinity, zmax = -Infinity, rmax = 0, count = 0;
    for (let i = 0; i < n; i++) {
      const x = lo[0] + pos[DIM * i] * dq[0], y = lo[1] + pos[DIM * i + 1] * dq[1];
      const z = DIM === 3 ? lo[2] + pos[DIM * i + 2] * dq[2] : 0;
      const q = proj.fn(x, y, z);
      if (persp && q[2] < 1e-3 * state.cam.dist) continue;  // behind the eye
      const r = Math.max(0.6, DATA.radius * q[3]);
      if (q[0] < -r || q[1] < -r || q[0] > p.w + r || q[1] > p.h + r) continue;
      sx[count] = q[0]; sy[count] = q[1]; sz[count] = q[2]; sr[count] = r; order[count] = i;
      hid[count] = occluding && hiddenBySolid(x, y, z, b3, persp, solids) ? 1 : 0;
      count++;
      if (q[2] < zmin) zmin = q[2];
      if (q[2] > zmax) zmax = q[2];
      if (r > rmax) rmax = r;
    }
    drawEdges(ctx, proj, 'back', dpr);
    const sp = getSprites(spriteSize(2 * Math.min(rmax, 64)));
    const S = sp.size;
    // Far to near (painter's algorithm): a counting sort of the depths into DEPTH_BINS bins.
    let idx = order;
    if (DIM === 3 && count > 1 && zmax > zmin) {
      binCount.fill(0);
      const k = (DEPTH_BINS - 1) / (zmax - zmin);
      for (let j = 0; j < count; j++) { const key = ((zmax - sz[j]) * k) | 0; keys[j] = key; binCount[key + 1]++; }
      for (let b = 1; b <= DEPTH_BINS; b++) binCount[b] += binCount[b - 1];
      idx = new Uint32Array(count);
      for (let j = 0; j < count; j++) idx[binCount[keys[j]]++] = j;
    } else {
      idx = new Uint32Array(count);
      for (let j = 0; j < count; j++) idx[j] = j;
    }
    const cols = sp.cols, img = sp.canvas;
    // 3D with obstacles: the particles behind them, the obstacles, the particles in front.
    // 2D: every particle, then the obstacles over them.
    for (const pass of occluding ? [1, 0] : [-1]) {
      if (pass === 0) drawSolids(ctx, proj, dpr, solids);
      for (let m = 0; m < count; m++) {
        const j = idx[m];
        if (pass >= 0 && hid[j] !== pass) continue;
        const b = bk[order[j]], r = sr[j];
        ctx.drawImage(img, (b % cols) * S, ((b / cols) | 0) * S, S, S, sx[j] - r, sy[j] - r, 2 * r, 2 * r);
      }
    }
    if (DIM === 2) drawSolids(ctx, proj, dpr, solids);
    drawEdges(ctx, proj, 'front', dpr);
    drawAxes(ctx, p, dpr);
  }

  let renderQueued = false;
  function render() {
    renderQueued = false;
    for (const p of panels) drawPanel(p);
    api.renders++;
  }
  function requestRender() {
    if (renderQueued) return;
    renderQueued = true;
    requestAnimationFrame(render);
  }

  // ---- number formatting -----------------------------------------------------------------------
  function fmt(v) {
    if (!isFinite(v)) return String(v);
    const a = Math.abs(v);
    if (a === 0) return '0';
    if (a >= 1e5 || a < 1e-3) return v.toExponential(2).replace('e+', 'e');
    return String(Number(v.toPrecision(3)));
  }

  // ---- controls --------------------------------------------------------------------------------
  const slider = $('slider'), playBtn = $('play');
  slider.max = String(FRAME_COUNT - 1);
  function setFrame(f) {
    f = Math.max(0, Math.min(FRAME_COUNT - 1, f));
    if (f === state.frame && slider.value === String(f) && $('frame-label').textContent) return;
    state.frame = f;
    slider.value = String(f);
    const fr = frameOf(RUNS[0], f);
    $('frame-label').textContent = `frame ${f + 1} / ${FRAME_COUNT}`;
    $('time-label').textContent = `t = ${fr.t.toFixed(3)} s`;
    $('time-label').title = `${fr.n} particles`;
    requestRender();
  }
  function setPlaying(on) {
    state.playing = on;
    playBtn.innerHTML = on ? '<svg viewBox="0 0 16 16" aria-hidden="true"><rect x="3" y="3" width="3.5" height="10"/><rect x="9.5" y="3" width="3.5" height="10"/></svg>'
                           : '<svg viewBox="0 0 16 16" aria-hidden="true"><path d="M4 2.5v11l9.5-5.5z"/></svg>';
    playBtn.classList.toggle('playing', on);
    playBtn.setAttribute('aria-label', on ? 'pause' : 'play');
    if (on) {
      if (state.frame >= FRAME_COUNT - 1) setFrame(0);
      lastTick = performance.now();
      elapsed = 0;
      requestAnimationFrame(tick);
    }
  }
  let lastTick = 0, elapsed = 0;
  // The time a frame stays on screen: 1 / fps, or the simulated time to the next frame.
  function frameDuration(f) {
    if (state.fps !== 'realtime') return 1 / state.fps;
    const fr = RUNS[0].frames;
    const a = fr[Math.min(f, fr.length - 1)].t, b = fr[Math.min(f + 1, fr.length - 1)].t;
    return b > a ? b - a : 1 / 25;
  }
  function tick(now) {
    if (!state.playing) return;
    elapsed += Math.min(0.25, (now - lastTick) / 1000);
    lastTick = now;
    let f = state.frame;
    while (elapsed >= frameDuration(f)) {
      elapsed -= frameDuration(f);
      if (f + 1 < FRAME_COUNT) f++;
      else if (state.loop) f = 0;
      else { setFrame(f); setPlaying(false); return; }
    }
    setFrame(f);
    requestAnimationFrame(tick);
  }

  function updateLegend() {
    const c = colorInfo.get(state.color);
    const bar = $('legend-bar'), ctx = bar.getContext('2d');
    const img = ctx.createImageData(bar.width, bar.height);
    for (let x = 0; x < bar.width; x++) {
      let rgb;
      if (c.scalar) {
        const k = 3 * Math.round(x / (bar.width - 1) * 255);
        rgb = [c.lutBytes[k], c.lutBytes[k + 1], c.lutBytes[k + 2]];
      }
      for (let y = 0; y < bar.height; y++) {
        if (!c.scalar) {  // one ramp per axis: red for x, green for y (and blue for z)
          const parts = DIM, k = Math.min(parts - 1, Math.floor(x * parts / bar.width));
          const t = (x - k * bar.width / parts) / (bar.width / parts - 1);
          rgb = [0, 0, 0];
          rgb = [40, 40, 40];  // as sph colors initial positions: 40 + 215 t per channel
          rgb[k] = 40 + 215 * Math.min(1, t);
        }
        const o = 4 * (y * bar.width + x);
        img.data[o] = rgb[0]; img.data[o + 1] = rgb[1]; img.data[o + 2] = rgb[2]; img.data[o + 3] = 255;
      }
    }
    ctx.putImageData(img, 0, 0);
    $('legend').classList.toggle('rgb', !c.scalar);
    $('legend-lo').textContent = c.scalar ? fmt(c.lo) : '';
    $('legend-hi').textContent = c.scalar ? fmt(c.hi) : '';
    $('legend-label').textContent = c.scalar ? c.label : DIM === 3 ? 'initial x \u2192 red, y \u2192 green, z \u2192 blue' : 'initial x \u2192 red, y \u2192 green';
    $('legend').title = c.scalar && c.clipped ? 'values above the range are shown in its top color' : '';
  }
  function setColor(name) {
    if (!colorInfo.has(name)) return;
    state.color = name;
    $('color').value = name;
    updateLegend();
    requestRender();
  }

  // Title, notes and selects.
  (function initUi() {
    const run0 = RUNS[0], first = run0.frames[0], last = run0.frames[run0.frames.length - 1];
    document.title = DATA.title ? `${DATA.title} - sph view` : 'sph view';
    $('title').textContent = DATA.title || 'sph run';
    const np = Math.max(...run0.frames.map((f) => f.n));
    const parts = [`${DIM}D`, `${np.toLocaleString('en-US')} particles`, `${FRAME_COUNT} frames, t = ${fmt(first.t)} to ${fmt(last.t)} s`];
    if (RUNS.length > 1) parts.push(`${RUNS.length} runs: ${RUNS.map((r) => r.label).join(', ')}`);
    if (DATA.description) parts.push(DATA.description);
    $('subtitle').textContent = parts.join(' \u00b7 ');
    $('subtitle').title = DATA.description || '';
    if (DATA.notes && DATA.notes.length) { $('note').hidden = false; $('note').textContent = DATA.notes.join(' '); }
    const sel = $('color');
    for (const c of DATA.colors) {
      const o = document.createElement('option');
      o.value = c.name;
      o.textContent = c.label;
      sel.append(o);
    }
    if (DIM === 2) {
      $('projection-group').hidden = true;
      $('help').innerHTML = 'drag: pan &middot; wheel: zoom &middot; double-click: reset view &middot; space: play &middot; &larr;&nbsp;&rarr;: step';
    }
  })();

  $('first').onclick = () => setFrame(0);
  $('last').onclick = () => setFrame(FRAME_COUNT - 1);
  $('prev').onclick = () => setFrame(state.frame - 1);
  $('next').onclick = () => setFrame(state.frame + 1);
  playBtn.onclick = () => setPlaying(!state.playing);
  slider.oninput = () => setFrame(Number(slider.value));
  $('speed').onchange = (e) => { state.fps = e.target.value === 'realtime' ? 'realtime' : Number(e.target.value); };
  $('loop').onchange = (e) => { state.loop = e.target.checked; };
  $('color').onchange = (e) => setColor(e.target.value);
  $('perspective').onchange = () => resetCamera();
  $('reset-camera').onclick = () => resetCamera();

  document.addEventListener('keydown', (e) => {
    if (e.target instanceof HTMLSelectElement || e.ctrlKey || e.metaKey || e.altKey) return;
    if (e.key === ' ') { setPlaying(!state.playing); e.preventDefault(); }
    else if (e.key === 'ArrowRight') { setFrame(state.frame + 1); e.preventDefault(); }
    else if (e.key === 'ArrowLeft') { setFrame(state.frame - 1); e.preventDefault(); }
    else if (e.key === 'Home') { setFrame(0); e.preventDefault(); }
    else if (e.key === 'End') { setFrame(FRAME_COUNT - 1); e.preventDefault(); }
    else if (e.key === 'r' || e.key === 'R') resetCamera();
  });
  // A focused button or slider would also react to space and the arrows: the page handles them.
  for (const el of document.querySelectorAll('button, input[type=range]'))
    el.addEventListener('keydown', (e) => { if ([' ', 'ArrowLeft', 'ArrowRight', 'Home', 'End'].includes(e.key)) e.preventDefault(); });

  // Mouse: orbit (3D) or pan (2D, or with shift / the right button); wheel zooms. Orbiting
  // one panel moves every panel's camera: they share one.
  for (const p of panels) {
    const c = p.canvas;
    let drag = null;
    c.addEventListener('contextmenu', (e) => e.preventDefault());
    c.addEventListener('pointerdown', (e) => {
      c.setPointerCapture(e.pointerId);
      c.classList.add('dragging');
      drag = { x: e.clientX, y: e.clientY, pan: DIM === 2 || e.shiftKey || e.button !== 0 };
    });
    c.addEventListener('pointermove', (e) => {
      if (!drag) return;
      const dx = e.clientX - drag.x, dy = e.clientY - drag.y, dpr = window.devicePixelRatio || 1;
      drag.x = e.clientX; drag.y = e.clientY;
      const cam = state.cam;
      if (drag.pan) {
        const s = projector(p).s / dpr;
        if (DIM === 2) { cam.pan[0] -= dx / s; cam.pan[1] += dy / s; }
        else {
          const b = basis(cam);
          for (let k = 0; k < 3; k++) cam.target[k] += (-dx * b.right[k] + dy * b.up[k]) / s;
        }
      } else {
        cam.yaw -= dx * 0.008;
        cam.pitch = Math.max(-1.55, Math.min(1.55, cam.pitch + dy * 0.008));
      }
      requestRender();
    });
    const end = () => { drag = null; c.classList.remove('dragging'); };
    c.addEventListener('pointerup', end);
    c.addEventListener('pointercancel', end);
    c.addEventListener('dblclick', () => resetCamera());
    c.addEventListener('wheel', (e) => {
      e.preventDefault();
      const k = Math.exp(Math.max(-0.5, Math.min(0.5, e.deltaY * 0.0015)));
      const cam = state.cam;
      if (DIM === 2) {
        // Zoom about the cursor: the world point under it stays put.
        const r = c.getBoundingClientRect(), dpr = window.devicePixelRatio || 1;
        const s0 = projector(p).s;
        const mx = (e.clientX - r.left) * dpr - p.w / 2, my = (e.clientY - r.top) * dpr - p.h / 2;
        cam.zoom = Math.max(0.2, Math.min(50, cam.zoom / k));
        const s1 = projector(p).s;
        cam.pan[0] += mx / s0 - mx / s1;
        cam.pan[1] -= my / s0 - my / s1;
      } else {
        cam.dist = Math.max(0.05 * fitDistance(), Math.min(20 * fitDistance(), cam.dist * k));
      }
      requestRender();
    }, { passive: false });
  }

  new ResizeObserver(() => { layout(); requestRender(); }).observe(panelsEl);
  layout();
  resetCamera();
  setColor(state.color);
  setPlaying(false);
  setFrame(0);
  render();
})();

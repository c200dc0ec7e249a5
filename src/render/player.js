// poolsim player: draws the moving part of the picture (balls, vectors, names, the lists under
// pocket and sector labels, the title and the counts) at any time, with the rules of
// src/render/svg.rs (moving_layer). The data is the JSON in #poolsim-data; nothing is fetched.
(function () {
  'use strict';
  const D = JSON.parse(document.getElementById('poolsim-data').textContent);
  const V = D.view;
  const C = D.consts;
  const svg = document.getElementById('pool');
  const dyn = document.getElementById('dyn');
  const $ = (id) => document.getElementById(id);
  const n = (x) => { const s = x.toFixed(2); return s === '-0.00' ? '0.00' : s; };
  const px = (x, y) => [V.left + (x - V.lo_x) * V.scale, V.top + (V.hi_y - y) * V.scale];
  const esc = (s) => String(s).replace(/&/g, '&amp;').replace(/</g, '&lt;').replace(/>/g, '&gt;');

  // As src/render/mod.rs format_time for frame times (one decimal where that is exact); other
  // times, met while playing, get four decimals.
  function fmtTime(t) {
    if (t === 0) t = 0;
    for (let d = 1; d <= 4; d++) {
      const p = Math.pow(10, d);
      if (Math.abs(Math.round(t * p) / p - t) <= 1e-9 * Math.max(Math.abs(t), 1)) return t.toFixed(d);
    }
    return t.toFixed(4);
  }

  // ---- state at any time ------------------------------------------------------------------
  const H = D.history;
  const F = D.frames;
  const nBalls = D.balls.length;

  // Last index k in [0, len) with key(k) <= t, or -1.
  function lastAtOrBefore(len, key, t) {
    let lo = 0, hi = len;
    while (lo < hi) { const mid = (lo + hi) >> 1; if (key(mid) <= t) lo = mid + 1; else hi = mid; }
    return lo - 1;
  }

  // Cumulative event counts by kind, for exact counts at any time.
  let cumulative = null;
  if (H) {
    const m = H.events.length;
    cumulative = D.event_kinds.map(() => new Int32Array(m + 1));
    for (let e = 0; e < m; e++) {
      for (let k = 0; k < cumulative.length; k++) cumulative[k][e + 1] = cumulative[k][e];
      cumulative[H.events[e][1]][e + 1] += 1;
    }
  }

  function frameIndex(t) {
    return Math.max(0, lastAtOrBefore(F.length, (k) => F[k].t, t));
  }

  // Every ball at time t, after every event up to and including t.
  function ballsAt(t) {
    const out = new Array(nBalls);
    if (H) {
      for (let i = 0; i < nBalls; i++) {
        const path = H.pieces[i];
        const k = Math.max(0, lastAtOrBefore(path.length, (j) => path[j][0], t));
        const p = path[k];
        if (p[6] !== null) out[i] = { x: p[1], y: p[2], vx: 0, vy: 0, pocket: p[6] };
        else out[i] = { x: p[1] + (t - p[3]) * p[4], y: p[2] + (t - p[3]) * p[5], vx: p[4], vy: p[5], pocket: null };
      }
      return out;
    }
    // No history (too long to embed): linear between frames.
    const k = frameIndex(t);
    const a = F[k], b = F[Math.min(k + 1, F.length - 1)];
    const s = b.t > a.t ? Math.min(1, Math.max(0, (t - a.t) / (b.t - a.t))) : 0;
    for (let i = 0; i < nBalls; i++) {
      const p = a.balls[i], q = b.balls[i];
      if (p[4] !== null) out[i] = { x: p[0], y: p[1], vx: 0, vy: 0, pocket: p[4] };
      else if (q[4] !== null) out[i] = { x: p[0] + (t - a.t) * p[2], y: p[1] + (t - a.t) * p[3], vx: p[2], vy: p[3], pocket: null };
      else out[i] = { x: p[0] + s * (q[0] - p[0]), y: p[1] + s * (q[1] - p[1]), vx: p[2], vy: p[3], pocket: null };
    }
    return out;
  }

  function eventsAt(t) {
    if (H) {
      const e = lastAtOrBefore(H.events.length, (j) => H.events[j][0], t) + 1;
      return cumulative.map((c) => c[e]);
    }
    return F[frameIndex(t)].events;
  }

  function messagesAt(t) {
    const f = F[frameIndex(t)];
    return f.messages ? { at: f.t, counts: f.messages } : null;
  }

  // ---- geometry of sectors (as src/polygon.rs: touches) --------------------------------------
  function orient(a, b, p) {
    const v = (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]);
    return v > 0 ? 1 : v < 0 ? -1 : 0;
  }
  function contains(pts, p) {
    let w = 0;
    for (let k = 0; k < pts.length; k++) {
      const a = pts[k], b = pts[(k + 1) % pts.length];
      const inBox = p[0] >= Math.min(a[0], b[0]) && p[0] <= Math.max(a[0], b[0]) &&
        p[1] >= Math.min(a[1], b[1]) && p[1] <= Math.max(a[1], b[1]);
      if (inBox && orient(a, b, p) === 0) return true;
      if (a[1] <= p[1]) { if (b[1] > p[1] && orient(a, b, p) > 0) w++; }
      else if (b[1] <= p[1] && orient(a, b, p) < 0) w--;
    }
    return w !== 0;
  }
  function segDist2(p, a, b) {
    const abx = b[0] - a[0], aby = b[1] - a[1];
    const len2 = abx * abx + aby * aby;
    let s = len2 > 0 ? ((p[0] - a[0]) * abx + (p[1] - a[1]) * aby) / len2 : 0;
    s = Math.max(0, Math.min(1, s));
    const dx = p[0] - (a[0] + s * abx), dy = p[1] - (a[1] + s * aby);
    return dx * dx + dy * dy;
  }
  function touches(sector, c, r) {
    const b = sector.bounds;
    if (c[0] < b[0] - r || c[0] > b[2] + r || c[1] < b[1] - r || c[1] > b[3] + r) return false;
    if (contains(sector.points, c)) return true;
    let d = Infinity;
    const pts = sector.points;
    for (let k = 0; k < pts.length; k++) d = Math.min(d, segDist2(c, pts[k], pts[(k + 1) % pts.length]));
    return d <= r * r;
  }
  for (const s of D.sectors) {
    let x0 = Infinity, y0 = Infinity, x1 = -Infinity, y1 = -Infinity;
    for (const p of s.points) { x0 = Math.min(x0, p[0]); y0 = Math.min(y0, p[1]); x1 = Math.max(x1, p[0]); y1 = Math.max(y1, p[1]); }
    s.bounds = [x0, y0, x1, y1];
  }

  // ---- drawing ------------------------------------------------------------------------------
  function firstBaseline(a, count, line, font) {
    const m = Math.max(count, 1);
    if (a.v === 'up') return a.y - (m - 1) * line - 2;
    if (a.v === 'down') return a.y + font;
    return a.y - (m - 1) * line / 2 + 0.35 * font;
  }
  function textBlock(a, lines, cls, fill, font) {
    const line = C.line * font / C.font;
    const y0 = firstBaseline(a, lines.length, line, font);
    let s = '<text class="' + cls + '" x="' + n(a.x) + '" y="' + n(y0) + '" text-anchor="' + a.h +
      '" font-size="' + n(font) + '" fill="' + fill + '"' +
      (cls.indexOf('sector-label') >= 0 || cls.indexOf('pocket-label') >= 0
        ? ' stroke="white" stroke-width="3" stroke-linejoin="round" paint-order="stroke"' : '') + '>';
    lines.forEach((l, i) => { s += '<tspan x="' + n(a.x) + '" y="' + n(y0 + i * line) + '">' + esc(l) + '</tspan>'; });
    return s + '</text>';
  }
  function listLines(label, names) {
    if (names.length > C.list_max) {
      const more = names.length - (C.list_max - 1);
      return [label].concat(names.slice(0, C.list_max - 1), ['\u2026 ' + more + ' more']);
    }
    return [label].concat(names);
  }
  function ballFont(rpx) { return Math.min(11, Math.max(7, rpx * 0.55)); }

  function countsLines(t, ev, msg) {
    const lines = ['events ' + ev.reduce((a, b) => a + b, 0) + ' (' +
      D.event_kinds.map((k, i) => k + ' ' + ev[i]).join(', ') + ')'];
    if (msg) {
      const parts = D.message_types.filter((k) => msg.counts[k] > 0).map((k) => k + ' ' + msg.counts[k]);
      const at = msg.at === t ? '' : ' at ' + fmtTime(msg.at);
      lines.push('messages' + at + ' ' + msg.counts.total + ' (' + parts.join(', ') + ')');
    }
    return lines;
  }

  const style = { vectors: C.vectors, labels: true, sectors: D.sectors.length > 0 };
  // As src/render/svg.rs arrow_head: the arrow cut where it leaves the table's box.
  function arrowHead(x, y, dx, dy) {
    const [lx, ly, hx, hy] = C.table_box;
    let s = 1;
    if (dx > 0 && x + dx > hx) s = Math.min(s, Math.max(0, (hx - x) / dx));
    else if (dx < 0 && x + dx < lx) s = Math.min(s, Math.max(0, (lx - x) / dx));
    if (dy > 0 && y + dy > hy) s = Math.min(s, Math.max(0, (hy - y) / dy));
    else if (dy < 0 && y + dy < ly) s = Math.min(s, Math.max(0, (ly - y) / dy));
    return [x + dx * s, y + dy * s];
  }
  let current = null;

  function draw(t) {
    const balls = ballsAt(t);
    const ev = eventsAt(t);
    const msg = messagesAt(t);
    const sectored = style.sectors && D.sectors.length > 0;
    const inSectors = balls.map((b, i) => (sectored && b.pocket === null)
      ? D.sectors.map((s, k) => touches(s, [b.x, b.y], D.balls[i].r) ? k : -1).filter((k) => k >= 0)
      : []);
    let s = '';
    // a reversal's last frame outlines where each ball started, beneath the balls
    if (D.turn && t === D.turn.end) {
      D.turn.starts.forEach((p, i) => {
        if (p === null) return;
        const [x, y] = px(p[0], p[1]);
        s += '<circle class="start" cx="' + n(x) + '" cy="' + n(y) + '" r="' + n(D.balls[i].r * V.scale + 3) +
          '" fill="none" stroke="' + C.colours.sector + '" stroke-width="1.5" stroke-dasharray="4 3"/>';
      });
    }
    balls.forEach((b, i) => {
      if (b.pocket !== null) return;
      const [x, y] = px(b.x, b.y);
      s += '<circle class="ball" data-ball="' + D.balls[i].name + '" cx="' + n(x) + '" cy="' + n(y) + '" r="' +
        n(D.balls[i].r * V.scale) + '" fill="' + (D.balls[i].colour || C.colours.ball) + '" stroke="black" stroke-width="1.5"/>';
      // a label (a pool ball's number) sits on a white disc, readable on any colour
      if (D.balls[i].label) {
        s += '<circle class="ball-disc" cx="' + n(x) + '" cy="' + n(y) + '" r="' + n(0.55 * D.balls[i].r * V.scale) +
          '" fill="white"/>';
      }
    });
    if (style.vectors) {
      balls.forEach((b, i) => {
        if (b.pocket !== null || (b.vx === 0 && b.vy === 0)) return;
        const [x, y] = px(b.x, b.y);
        const head = arrowHead(b.x, b.y, b.vx * C.arrow_time, b.vy * C.arrow_time);
        const [hx, hy] = px(head[0], head[1]);
        s += '<line class="velocity" data-ball="' + D.balls[i].name + '" x1="' + n(x) + '" y1="' + n(y) + '" x2="' +
          n(hx) + '" y2="' + n(hy) + '" stroke="' + C.colours.vector +
          '" stroke-width="1.5" marker-end="url(#poolsim-arrow)"/>';
      });
    }
    if (style.labels) {
      if (C.names_balls) {
        balls.forEach((b, i) => {
          if (b.pocket !== null || D.balls[i].label === '') return;
          const [x, y] = px(b.x, b.y);
          const first = D.balls[i].label === null || D.balls[i].label === undefined ? D.balls[i].name : D.balls[i].label;
          const lines = [first].concat(inSectors[i].map((k) => D.sectors[k].name));
          s += textBlock({ x: x, y: y, h: 'middle', v: 'center' }, lines, 'label ball-label', C.colours.text,
            ballFont(D.balls[i].r * V.scale));
        });
      }
      if (sectored) {
        D.sectors.forEach((sec, k) => {
          const names = [];
          balls.forEach((b, i) => { if (inSectors[i].indexOf(k) >= 0) names.push(D.balls[i].name); });
          s += textBlock(sec.anchors[0], listLines(sec.name, names), 'label sector-label', C.colours.sector, C.font);
        });
      }
    }
    D.pockets.forEach((p, k) => {
      const names = [];
      balls.forEach((b, i) => { if (b.pocket === k) names.push(D.balls[i].name); });
      s += textBlock(p.anchor, listLines(p.name, names), 'pocket-label', C.colours.text, C.font);
    });
    s += textBlock({ x: V.width / 2, y: 14, h: 'middle', v: 'down' }, ['POOL SIMULATION AT ' + fmtTime(t)], 'title',
      C.colours.text, 22);
    const mirror = mirrorDistance(t, balls);
    if (D.turn) {
      s += textBlock({ x: V.width / 2, y: 40, h: 'middle', v: 'down' }, [turnLine(t, mirror)], 'turn', C.colours.quiet,
        C.font);
    }
    s += textBlock({ x: 12, y: V.height - 8, h: 'start', v: 'up' }, countsLines(t, ev, msg), 'counts',
      C.colours.quiet, 11);
    dyn.innerHTML = s;
    unclutter();
    current = { t: t, balls: balls, events: ev, messages: msg, mirror: mirror };
    $('mirror').textContent = mirror === null ? '' : '\u2194 ' + fmtDistance(mirror) + ' from t = ' +
      fmtTime(2 * D.turn.at - t);
    showCounts(ev, msg);
  }

  // A sector's label stands at the first of its anchors where it covers no named ball nor
  // another sector's label; else its name alone at the first such anchor; else nowhere. What it
  // does not show, it shows on hover over the sector's outline. SVG and PNG frames follow the
  // same rule with text widths from the font's metrics.
  function unclutter() {
    const taken = Array.from(dyn.querySelectorAll('text.ball-label')).map((e) => e.getBBox());
    if (taken.length > 0) dyn.querySelectorAll('circle.ball').forEach((e) => taken.push(e.getBBox()));
    const meets = (a, b) => a.x < b.x + b.width && b.x < a.x + a.width && a.y < b.y + b.height && b.y < a.y + a.height;
    const free = (box) => !taken.some((b) => meets(box, b));
    const outlines = svg.querySelectorAll('.sector');
    Array.from(dyn.querySelectorAll('text.sector-label')).forEach((e, k) => {
      const stale = outlines[k] && outlines[k].querySelector('title');
      if (stale) stale.remove();
      const spans = Array.from(e.querySelectorAll('tspan'));
      const text = spans.map((t) => t.textContent).join('\n');
      const fits = () => D.sectors[k].anchors.some((a) => { moveBlock(e, a, C.font); return free(e.getBBox()); });
      const whole = fits();
      if (!whole) spans.slice(1).forEach((t) => t.remove());
      if (whole || fits()) taken.push(e.getBBox()); else e.remove();
      if (!whole && outlines[k]) {
        let title = outlines[k].querySelector('title');
        if (!title) { title = document.createElementNS(svg.namespaceURI, 'title'); outlines[k].appendChild(title); }
        title.textContent = text;
      }
    });
  }
  // Moves a text block written by textBlock to anchor a.
  function moveBlock(e, a, font) {
    const spans = Array.from(e.querySelectorAll('tspan'));
    const line = C.line * font / C.font;
    const y0 = firstBaseline(a, spans.length, line, font);
    e.setAttribute('x', n(a.x));
    e.setAttribute('y', n(y0));
    spans.forEach((t, i) => { t.setAttribute('x', n(a.x)); t.setAttribute('y', n(y0 + i * line)); });
  }

  // ---- the side panel -----------------------------------------------------------------------
  function showCounts(ev, msg) {
    let h = '<tr><th colspan="2">events up to now</th></tr>';
    D.event_kinds.forEach((k, i) => { h += '<tr><td>' + k + '</td><td>' + ev[i] + '</td></tr>'; });
    h += '<tr><td><b>total</b></td><td><b>' + ev.reduce((a, b) => a + b, 0) + '</b></td></tr>';
    if (msg) {
      h += '<tr><th colspan="2">messages sent up to frame ' + fmtTime(msg.at) + '</th></tr>';
      D.message_types.forEach((k) => { h += '<tr><td>' + k + '</td><td>' + msg.counts[k] + '</td></tr>'; });
      h += '<tr><td><b>total (thesis table 5)</b></td><td><b>' + msg.counts.total + '</b></td></tr>';
    } else {
      h += '<tr><th colspan="2">messages</th></tr><tr><td colspan="2">the ' + esc(D.engine) +
        ' engine sends none</td></tr>';
    }
    $('counts').innerHTML = h;
  }

  // ---- the reversal -------------------------------------------------------------------------
  // After the reversal at r, at r + t: the largest distance between a ball on the table and
  // where it was at r - t (null before the reversal, or where r - t is before the start).
  function mirrorDistance(t, balls) {
    if (!D.turn || t < D.turn.at || 2 * D.turn.at - t < D.start) return null;
    const then = ballsAt(2 * D.turn.at - t);
    let far = 0;
    balls.forEach((b, i) => {
      const a = then[i];
      if (b.pocket === null && a.pocket === null) far = Math.max(far, Math.hypot(b.x - a.x, b.y - a.y));
    });
    return far;
  }
  function fmtDistance(d) { return d === 0 ? '0' : d.toExponential(1); }
  // As src/render/svg.rs turn_line.
  function turnLine(t, mirror) {
    const at = fmtTime(D.turn.at);
    if (t >= D.turn.at && mirror !== null) {
      return 'turned around at ' + at + ': the farthest any ball is from where it was at ' +
        fmtTime(2 * D.turn.at - t) + ' is ' + fmtDistance(mirror);
    }
    return t >= D.turn.at ? 'turned around at ' + at : 'every ball turns around at ' + at;
  }

  // ---- controls -----------------------------------------------------------------------------
  let t = D.start, playing = false, last = null;
  const slider = $('time');
  slider.min = String(D.start);
  slider.max = String(D.until);
  slider.value = String(D.start);
  slider.step = String(D.until > D.start ? (D.until - D.start) / 4000 : 1);

  function seek(x) {
    const v = Number(x);
    if (!isFinite(v)) throw new Error('seek: not a number: ' + x);
    t = Math.min(D.until, Math.max(D.start, v));
    slider.value = String(t);
    $('clock').textContent = fmtTime(t);
    draw(t);
    return state();
  }
  function state() {
    return {
      t: current.t,
      balls: current.balls.map((b, i) => ({ name: D.balls[i].name, x: b.x, y: b.y, vx: b.vx, vy: b.vy,
        pocket: b.pocket === null ? null : D.pocket_names[b.pocket] })),
      events: Object.fromEntries(D.event_kinds.map((k, i) => [k, current.events[i]])),
      messages: current.messages ? current.messages.counts : null,
      mirror_distance: current.mirror,
      exact: !!H,
    };
  }
  // Where things landed on the screen, in CSS pixels (for the headless tests of the layout).
  function layout() {
    const box = (e) => { const r = e.getBoundingClientRect(); return [r.left, r.top, r.right, r.bottom]; };
    const [x0, y0] = px(C.table_box[0], C.table_box[3]);
    const [x1, y1] = px(C.table_box[2], C.table_box[1]);
    const m = svg.getScreenCTM();
    const screen = (x, y) => { const p = svg.createSVGPoint(); p.x = x; p.y = y; const q = p.matrixTransform(m); return [q.x, q.y]; };
    return {
      window: [window.innerWidth, window.innerHeight],
      table: screen(x0, y0).concat(screen(x1, y1)),
      labels: Array.from(svg.querySelectorAll('text.label, text.pocket-label')).map(box),
      arrows: Array.from(svg.querySelectorAll('line.velocity')).map((l) =>
        screen(+l.getAttribute('x1'), +l.getAttribute('y1')).concat(screen(+l.getAttribute('x2'), +l.getAttribute('y2')))),
      counts: box(svg.querySelector('text.counts')),
    };
  }
  function tick(now) {
    if (!playing) return;
    if (last !== null) {
      let next = t + (now - last) / 1000 * Number($('speed').value);
      if (next >= D.until) {
        if ($('loop').checked) next = D.start; else { next = D.until; pause(); }
      }
      seek(next);
    }
    last = now;
    if (playing) requestAnimationFrame(tick);
  }
  function play() {
    if (t >= D.until) seek(D.start);
    playing = true; last = null; $('play').textContent = 'Pause';
    requestAnimationFrame(tick);
  }
  function pause() { playing = false; $('play').textContent = 'Play'; }
  function stepFrames(k) {
    pause();
    const i = frameIndex(t);
    const j = Math.min(F.length - 1, Math.max(0, (F[i].t < t && k < 0) ? i : i + k));
    seek(F[j].t);
  }

  $('play').addEventListener('click', () => (playing ? pause() : play()));
  $('back').addEventListener('click', () => stepFrames(-1));
  $('fwd').addEventListener('click', () => stepFrames(1));
  slider.addEventListener('input', () => { pause(); seek(slider.value); });
  function toggles() {
    style.sectors = $('show-sectors').checked;
    style.vectors = $('show-vectors').checked;
    style.labels = $('show-labels').checked;
    svg.classList.toggle('hide-sectors', !style.sectors);
    svg.classList.toggle('hide-labels', !style.labels);
    draw(t);
  }
  ['show-sectors', 'show-vectors', 'show-labels'].forEach((id) => $(id).addEventListener('change', toggles));
  if (D.sectors.length === 0) { $('show-sectors').checked = false; $('show-sectors').disabled = true; }
  $('show-vectors').checked = C.vectors;
  document.addEventListener('keydown', (e) => {
    if (e.target && e.target.tagName === 'SELECT') return;
    if (e.key === ' ') { e.preventDefault(); playing ? pause() : play(); }
    else if (e.key === 'ArrowRight') stepFrames(1);
    else if (e.key === 'ArrowLeft') stepFrames(-1);
  });

  $('mode').textContent = H
    ? 'Exact at any time: the run\u2019s trajectories are in the page.'
    : 'Between frames, positions are interpolated linearly and counts are those of the last ' +
      'frame (the run\u2019s trajectories were too long to put in the page).';

  window.poolsim = { seek: seek, state: state, play: play, pause: pause, data: D };

  // ?t=T seeks and stays paused; &dump=1 writes state() into #poolsim-state (for headless tests).
  const q = new URLSearchParams(window.location.search);
  toggles();
  if (q.has('t')) {
    seek(q.get('t'));
    if (q.get('dump') === '1') {
      const pre = $('poolsim-state');
      pre.textContent = JSON.stringify(Object.assign(state(), { layout: layout() }));
      pre.hidden = false;
    }
  } else {
    seek(D.start);
    play();
  }
})();

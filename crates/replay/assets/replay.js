// The flight replay (trust-replay): draws the embedded run-log data on 2-D canvases.
// No network access: everything this page needs is in this file and the JSON element above it.
(function () {
  'use strict';
  var statusEl = document.getElementById('replay-status');
  var status = { errors: [], ready: false, t: 0, vehicle_px: [0, 0], vehicle: [0, 0, 0] };
  function writeStatus() { statusEl.textContent = JSON.stringify(status); }
  function report(message) {
    status.errors.push(String(message));
    writeStatus();
    var box = document.getElementById('errors');
    box.hidden = false;
    box.textContent = status.errors.join('\n');
  }
  window.addEventListener('error', function (e) { report('error: ' + (e.message || e.type)); });
  window.addEventListener('unhandledrejection', function (e) { report('unhandled rejection: ' + e.reason); });
  var consoleError = console.error;
  console.error = function () {
    report('console.error: ' + Array.prototype.join.call(arguments, ' '));
    consoleError.apply(console, arguments);
  };
  writeStatus();

  var COLORS = {
    static: 'rgba(90,90,90,0.75)', points: 'rgba(90,90,90,0.55)', path: '#111', pathAll: 'rgba(0,0,0,0.12)',
    vehicle: '#0a5ac8', truth: 'rgba(204,51,17,0.55)', truthEdge: '#cc3311', forecast: '#ee9900',
    main: '#0a5ac8', other: 'rgba(120,80,160,0.75)', route: '#009e73', start: '#009e73', goal: '#d55e00'
  };
  var EVENT_ROWS = [
    ['switched', '#0a5ac8'], ['fallback', '#cc3311'], ['stalled', '#ee9900'], ['escaped', '#009e73'],
    ['repaired', '#8e44ad'], ['dropped_collision', '#888888'], ['solve_failed', '#444444'], ['frontend_failed', '#444444']
  ];

  function main() {
    var D = JSON.parse(document.getElementById('replay-data').textContent);
    var H = D.header, S = D.states, C = D.cycles || [];
    var n = S.t.length;
    var t0 = S.t[0], t1 = S.t[n - 1];
    var b = H.bounds;

    // ---- geometry helpers ----
    function lerp(a, c, u) { return a + (c - a) * u; }
    function stateIndex(t) { // last kept state with time <= t
      var lo = 0, hi = n - 1;
      if (t <= S.t[0]) { return 0; }
      while (lo < hi) { var mid = (lo + hi + 1) >> 1; if (S.t[mid] <= t) { lo = mid; } else { hi = mid - 1; } }
      return lo;
    }
    function cycleIndex(t) { // last cycle with time <= t, -1 before the first
      var lo = -1, hi = C.length - 1;
      while (lo < hi) { var mid = (lo + hi + 1) >> 1; if (C[mid].t <= t + 1e-9) { lo = mid; } else { hi = mid - 1; } }
      return lo;
    }
    function interp(arr, i, u) { // arr[i] .. arr[i+1], element-wise
      if (i + 1 >= arr.length) { return arr[i]; }
      var a = arr[i], c = arr[i + 1], out = [];
      for (var k = 0; k < a.length; k++) { out.push(lerp(a[k], c[k], u)); }
      return out;
    }

    // ---- a view: world axes (ax, ay) onto a canvas, equal scale; the window can follow the vehicle ----
    function View(canvas, ax, ay, maxW, maxH) {
      var pad = { l: 44, r: 10, t: 10, b: 28 };
      var wx = b.max[ax] - b.min[ax], wy = b.max[ay] - b.min[ay];
      var scale = Math.min((maxW - pad.l - pad.r) / wx, (maxH - pad.t - pad.b) / wy);
      canvas.width = Math.round(wx * scale + pad.l + pad.r);
      canvas.height = Math.max(120, Math.round(wy * scale + pad.t + pad.b));
      this.canvas = canvas; this.ctx = canvas.getContext('2d');
      this.ax = ax; this.ay = ay; this.pad = pad;
      this.plotW = canvas.width - pad.l - pad.r; this.plotH = canvas.height - pad.t - pad.b;
      this.background = document.createElement('canvas');
      this.background.width = canvas.width; this.background.height = canvas.height;
      this.setWindow(b.min[ax], b.max[ax], b.min[ay], b.max[ay]);
    }
    // Shows [x0, x1] × [y0, y1] (grown to the canvas's aspect around its centre).
    View.prototype.setWindow = function (x0, x1, y0, y1) {
      var scale = Math.min(this.plotW / (x1 - x0), this.plotH / (y1 - y0));
      var cx = 0.5 * (x0 + x1), cy = 0.5 * (y0 + y1);
      var w = { x0: cx - 0.5 * this.plotW / scale, y0: cy - 0.5 * this.plotH / scale };
      w.x1 = w.x0 + this.plotW / scale; w.y1 = w.y0 + this.plotH / scale;
      var key = [w.x0, w.y0, scale].map(function (v) { return v.toFixed(4); }).join();
      if (key === this.key) { return; }
      this.key = key; this.win = w; this.scale = scale; this.dirty = true;
      var pad = this.pad, h = this.canvas.height;
      this.x = function (v) { return pad.l + (v - w.x0) * scale; };
      this.y = function (v) { return h - pad.b - (v - w.y0) * scale; };
    };
    View.prototype.px = function (p) { return [this.x(p[this.ax]), this.y(p[this.ay])]; };
    View.prototype.axes = function (g) {
      var self = this, c = this.canvas, w = this.win;
      g.strokeStyle = '#ddd'; g.fillStyle = '#555'; g.lineWidth = 1; g.font = '11px sans-serif';
      function ticks(lo, hi) {
        var span = hi - lo, step = Math.pow(10, Math.floor(Math.log10(span)));
        if (span / step < 4) { step /= 2; } else if (span / step > 10) { step *= 2; }
        var out = []; for (var v = Math.ceil(lo / step) * step; v <= hi + 1e-9; v += step) { out.push(+v.toFixed(6)); }
        return out;
      }
      var names = ['x', 'y', 'z'];
      ticks(w.x0, w.x1).forEach(function (v) {
        var x = self.x(v); g.beginPath(); g.moveTo(x, self.pad.t); g.lineTo(x, c.height - self.pad.b); g.stroke();
        g.textAlign = 'center'; g.fillText(String(v), x, c.height - self.pad.b + 14);
      });
      ticks(w.y0, w.y1).forEach(function (v) {
        var y = self.y(v); g.beginPath(); g.moveTo(self.pad.l, y); g.lineTo(c.width - self.pad.r, y); g.stroke();
        g.textAlign = 'right'; g.fillText(String(v), self.pad.l - 4, y + 4);
      });
      g.textAlign = 'left';
      g.fillText(names[this.ax] + ' [m]', c.width - this.pad.r - 34, c.height - 2);
      g.fillText(names[this.ay] + ' [m]', 2, 10);
      g.strokeStyle = '#999';
      g.strokeRect(this.x(b.min[this.ax]), this.y(b.max[this.ay]), (b.max[this.ax] - b.min[this.ax]) * this.scale, (b.max[this.ay] - b.min[this.ay]) * this.scale);
    };
    View.prototype.circle = function (g, p, r, fill, stroke, width) {
      var q = this.px(p);
      g.beginPath(); g.arc(q[0], q[1], Math.max(r * this.scale, 1.5), 0, 2 * Math.PI);
      if (fill) { g.fillStyle = fill; g.fill(); }
      if (stroke) { g.strokeStyle = stroke; g.lineWidth = width || 1; g.stroke(); }
    };
    View.prototype.rect = function (g, lo, hi, fill, stroke, width) { // lo/hi: 3-D corners
      var x0 = this.x(lo[this.ax]), x1 = this.x(hi[this.ax]), y0 = this.y(lo[this.ay]), y1 = this.y(hi[this.ay]);
      if (fill) { g.fillStyle = fill; g.fillRect(x0, y1, x1 - x0, y0 - y1); }
      if (stroke) { g.strokeStyle = stroke; g.lineWidth = width || 1; g.strokeRect(x0, y1, x1 - x0, y0 - y1); }
    };
    // A shape centred at c: sphere (r), vertical cylinder (r, half height hh), or box (half extents he).
    View.prototype.shape = function (g, c, s, fill, stroke, width) {
      if (s.he) {
        this.rect(g, [c[0] - s.he[0], c[1] - s.he[1], c[2] - s.he[2]], [c[0] + s.he[0], c[1] + s.he[1], c[2] + s.he[2]], fill, stroke, width);
      } else if (s.hh !== undefined && this.ay === 2) {
        this.rect(g, [c[0] - s.r, c[1] - s.r, c[2] - s.hh], [c[0] + s.r, c[1] + s.r, c[2] + s.hh], fill, stroke, width);
      } else {
        this.circle(g, c, s.r, fill, stroke, width);
      }
    };
    View.prototype.line = function (g, pts, color, width, dash) { // pts: [[x, y, z], ...]
      if (!pts || pts.length < 2) { return; }
      var o = 0, self = this;
      g.beginPath();
      pts.forEach(function (p, i) {
        var x = self.x(p[o + self.ax]), y = self.y(p[o + self.ay]);
        if (i === 0) { g.moveTo(x, y); } else { g.lineTo(x, y); }
      });
      g.strokeStyle = color; g.lineWidth = width; g.setLineDash(dash || []); g.stroke(); g.setLineDash([]);
    };
    View.prototype.star = function (g, p, r, color) {
      var q = this.px(p);
      g.beginPath();
      for (var i = 0; i < 10; i++) {
        var a = -Math.PI / 2 + i * Math.PI / 5, rr = i % 2 ? r * 0.45 : r;
        g.lineTo(q[0] + rr * Math.cos(a), q[1] + rr * Math.sin(a));
      }
      g.closePath(); g.fillStyle = color; g.fill();
    };

    // ---- static layer (drawn once per view) ----
    function staticLayer(v) {
      var g = v.background.getContext('2d');
      g.save();
      g.fillStyle = '#fff'; g.fillRect(0, 0, v.background.width, v.background.height);
      v.axes(g);
      g.beginPath(); g.rect(v.pad.l, v.pad.t, v.plotW, v.plotH); g.clip();
      (D.points || []).forEach(function (p) {
        var q = v.px(p); g.fillStyle = COLORS.points; g.fillRect(q[0] - 0.5, q[1] - 0.5, 1.2, 1.2);
      });
      (H.static_shapes || []).forEach(function (s) {
        if (s.sphere) { v.circle(g, s.sphere.center, s.sphere.radius, COLORS.static); }
        else if (s.cylinder) {
          var c = s.cylinder;
          v.shape(g, [c.center[0], c.center[1], 0.5 * (c.z_min + c.z_max)], { r: c.radius, hh: 0.5 * (c.z_max - c.z_min) }, COLORS.static);
        } else if (s.box) { v.rect(g, s.box.min, s.box.max, COLORS.static); }
      });
      v.line(g, S.p, COLORS.pathAll, 2);
      var q = v.px(H.start);
      g.beginPath(); g.arc(q[0], q[1], 5, 0, 2 * Math.PI); g.fillStyle = COLORS.start; g.fill();
      v.star(g, H.goal, 9, COLORS.goal);
      g.beginPath(); var gq = v.px(H.goal);
      g.arc(gq[0], gq[1], Math.max(H.goal_tolerance * v.scale, 2), 0, 2 * Math.PI);
      g.strokeStyle = COLORS.goal; g.setLineDash([3, 3]); g.lineWidth = 1; g.stroke(); g.setLineDash([]);
      g.restore();
      v.dirty = false;
    }

    function obstacleShape(info) {
      if (info.half_extents) { return { he: info.half_extents }; }
      if (info.shape === 'cylinder') { return { r: info.radius, hh: info.half_height || 0 }; }
      return { r: info.radius };
    }
    // f = [id, x, y, z, vx, vy, vz, t0, r0, mu, half_height (0: sphere),
    //      growth_s (null: grows for ever), walls ([min, max] of the region the planner mirrors
    //      the forecast in; null: the world's bounds)]
    function forecastAt(f, t) {
      var dt = Math.max(0, t - f[7]);
      var c = [f[1] + f[4] * dt, f[2] + f[5] * dt, f[3] + f[6] * dt];
      var grown = f[9] * (f[11] == null ? dt : Math.min(dt, f[11]));
      var s = { r: f[8] + grown };
      if (f[10] > 0) { s.hh = f[10] + grown; }
      return { c: c, s: s };
    }
    function latestRoute(ci) {
      for (var i = ci; i >= 0; i--) { if (C[i].route) { return C[i].route; } }
      return H.route || null;
    }

    // ---- the views: side by side, or stacked at full width for an elongated world (E4) ----
    var topCanvas = document.getElementById('top'), sideCanvas = document.getElementById('side');
    var wide = (b.max[0] - b.min[0]) > 2.2 * (b.max[1] - b.min[1]);
    var topView = new View(topCanvas, 0, 1, wide ? 1280 : 620, 560);
    var sideView = new View(sideCanvas, 0, 2, wide ? 1280 : 620, 260);
    var zoomSel = document.getElementById('zoom');
    function frameViews(p) { // the window of the zoom setting around p
      var z = parseFloat(zoomSel.value);
      if (!(z > 0)) {
        topView.setWindow(b.min[0], b.max[0], b.min[1], b.max[1]);
        sideView.setWindow(b.min[0], b.max[0], b.min[2], b.max[2]);
        return;
      }
      var hy = 0.5 * z * topView.plotH / topView.plotW;
      topView.setWindow(p[0] - 0.5 * z, p[0] + 0.5 * z, p[1] - hy, p[1] + hy);
      sideView.setWindow(p[0] - 0.5 * z, p[0] + 0.5 * z, b.min[2], b.max[2]);
    }

    function drawView(v, t, si, u, ci) {
      var g = v.ctx;
      if (v.dirty) { staticLayer(v); }
      g.drawImage(v.background, 0, 0);
      g.save();
      g.beginPath(); g.rect(v.pad.l, v.pad.t, v.plotW, v.plotH); g.clip();
      var route = latestRoute(ci);
      if (route) { v.line(g, route, COLORS.route, 2, [8, 5]); }
      // flown path so far
      v.line(g, S.p.slice(0, si + 1).concat([interp(S.p, si, u)]), COLORS.path, 2);
      // true obstacles
      var next = S.obstacles[Math.min(si + 1, n - 1)];
      (H.obstacles || []).forEach(function (info, i) {
        var a = S.obstacles[si][i], c = next[i];
        if (!a) { return; }
        var p = [lerp(a[0], c[0], u), lerp(a[1], c[1], u), lerp(a[2], c[2], u)];
        v.shape(g, p, obstacleShape(info), COLORS.truth, COLORS.truthEdge, 1);
      });
      var cyc = ci >= 0 ? C[ci] : null;
      // forecasts: now (solid) and 1 s, 2 s ahead (fading), centre line from t0
      if (cyc && cyc.forecasts) {
        var regions = {};
        cyc.forecasts.forEach(function (f) {
          if (!f[12]) { return; }
          var key = JSON.stringify(f[12]);
          if (regions[key]) { return; }
          regions[key] = true;
          g.setLineDash([6, 4]);
          v.rect(g, f[12][0], f[12][1], null, COLORS.forecast, 1);
          g.setLineDash([]);
        });
        cyc.forecasts.forEach(function (f) {
          var now = forecastAt(f, t);
          [2, 1].forEach(function (ahead) {
            var fa = forecastAt(f, t + ahead);
            g.globalAlpha = ahead === 1 ? 0.45 : 0.25;
            v.shape(g, fa.c, fa.s, null, COLORS.forecast, 1);
          });
          g.globalAlpha = 1;
          v.line(g, [[f[1], f[2], f[3]], forecastAt(f, t + 2).c], COLORS.forecast, 1, [2, 3]);
          v.shape(g, now.c, now.s, null, COLORS.forecast, 2);
          var q = v.px(now.c); g.fillStyle = COLORS.forecast; g.fillRect(q[0] - 2, q[1] - 2, 4, 4);
        });
      }
      // branches: the others, then the main one on top
      if (cyc && cyc.branches) {
        var hasMain = cyc.main !== null && cyc.main !== undefined;
        cyc.branches.forEach(function (br, k) {
          if (k === 0 && hasMain) { return; }
          v.line(g, br, COLORS.other, 1.5, [5, 4]);
        });
        if (hasMain && cyc.branches.length) { v.line(g, cyc.branches[0], COLORS.main, 3); }
      }
      // the vehicle
      var p = interp(S.p, si, u);
      v.circle(g, p, H.vehicle.radius, 'rgba(10,90,200,0.35)', COLORS.vehicle, 2);
      var q = v.px(p);
      g.beginPath(); g.arc(q[0], q[1], 3, 0, 2 * Math.PI); g.fillStyle = COLORS.vehicle; g.fill();
      g.restore();
      return q;
    }

    // ---- timeline and traces ----
    var timeline = document.getElementById('timeline'), traces = document.getElementById('traces');
    var TL = { l: 120, r: 16 };
    function tx(canvas, t) { return TL.l + (t - t0) / Math.max(t1 - t0, 1e-9) * (canvas.width - TL.l - TL.r); }
    function tOf(canvas, x) { return t0 + (x - TL.l) / (canvas.width - TL.l - TL.r) * (t1 - t0); }
    var timelineBg = document.createElement('canvas');
    timelineBg.width = timeline.width; timelineBg.height = timeline.height;
    (function () {
      var g = timelineBg.getContext('2d'), rowH = (timeline.height - 16) / EVENT_ROWS.length;
      g.fillStyle = '#fff'; g.fillRect(0, 0, timeline.width, timeline.height);
      g.font = '10px sans-serif';
      EVENT_ROWS.forEach(function (row, k) {
        var y = 4 + k * rowH;
        g.fillStyle = row[1]; g.textAlign = 'right'; g.fillText(row[0], TL.l - 6, y + rowH - 2);
        C.forEach(function (c) {
          if (c.events.indexOf(row[0]) >= 0) { g.fillRect(tx(timeline, c.t) - 1, y + 1, 2.5, rowH - 2); }
        });
      });
      g.fillStyle = '#555'; g.textAlign = 'center';
      for (var s = Math.ceil(t0); s <= t1; s += (t1 - t0 > 30 ? 5 : 1)) { g.fillText(String(s), tx(timeline, s), timeline.height - 2); }
    })();
    var tracesBg = document.createElement('canvas');
    tracesBg.width = traces.width; tracesBg.height = traces.height;
    var finite = function (x) { return x !== null && isFinite(x); };
    (function () {
      var g = tracesBg.getContext('2d'), half = traces.height / 2;
      g.fillStyle = '#fff'; g.fillRect(0, 0, traces.width, traces.height);
      g.font = '11px sans-serif';
      function panel(y0, h, series, lines, label) {
        var lo = 0, hi = 0;
        series.forEach(function (s) { s.v.forEach(function (x) { if (finite(x)) { hi = Math.max(hi, x); lo = Math.min(lo, x); } }); });
        lines.forEach(function (l) { hi = Math.max(hi, l.v); lo = Math.min(lo, l.v); });
        hi = hi + 0.05 * (hi - lo + 1e-9);
        var y = function (x) { return y0 + h - 6 - (x - lo) / (hi - lo) * (h - 14); };
        g.strokeStyle = '#ddd'; g.strokeRect(TL.l, y0 + 4, traces.width - TL.l - TL.r, h - 8);
        g.fillStyle = '#222'; g.textAlign = 'right'; g.fillText(label, TL.l - 6, y0 + 16);
        g.fillStyle = '#777'; g.fillText(hi.toFixed(1), TL.l - 6, y0 + 30); g.fillText(lo.toFixed(1), TL.l - 6, y0 + h - 6);
        lines.forEach(function (l) {
          g.strokeStyle = l.c; g.setLineDash([4, 3]); g.beginPath(); g.moveTo(TL.l, y(l.v)); g.lineTo(traces.width - TL.r, y(l.v)); g.stroke(); g.setLineDash([]);
          g.fillStyle = l.c; g.textAlign = 'left'; g.fillText(l.name, TL.l + 4, y(l.v) - 3);
        });
        series.forEach(function (s, k) {
          g.strokeStyle = s.c; g.lineWidth = 1.5; g.beginPath();
          var pen = false;
          s.v.forEach(function (x, i) {
            if (!finite(x)) { pen = false; return; }
            var px = tx(traces, S.t[i]), py = y(Math.min(x, hi));
            if (pen) { g.lineTo(px, py); } else { g.moveTo(px, py); pen = true; }
          });
          g.stroke(); g.lineWidth = 1;
          g.fillStyle = s.c; g.textAlign = 'right'; g.fillText(s.name, traces.width - TL.r - 4, y0 + 16 + 12 * k);
        });
      }
      panel(0, half, [{ v: S.speed, c: '#0a5ac8', name: '|v| [m/s]' }], [{ v: H.limits.v_max, c: '#cc3311', name: 'v_max' }], 'speed');
      var capped = function (k) { return S.clear.map(function (c) { return finite(c[k]) ? Math.min(c[k], 5) : null; }); };
      panel(half, half, [{ v: capped(0), c: '#555', name: 'static [m]' }, { v: capped(1), c: '#cc3311', name: 'moving [m]' }],
        [{ v: 0, c: '#000', name: 'clearance 0' }], 'clearance');
    })();

    function drawCursor(canvas, bg, t) {
      var g = canvas.getContext('2d');
      g.drawImage(bg, 0, 0);
      var x = tx(canvas, t);
      g.strokeStyle = '#000'; g.lineWidth = 1.5; g.beginPath(); g.moveTo(x, 0); g.lineTo(x, canvas.height); g.stroke(); g.lineWidth = 1;
    }

    // ---- legend and summary ----
    var legend = document.getElementById('legend');
    [['flown path', COLORS.path], ['vehicle', COLORS.vehicle], ['main branch', COLORS.main], ['other branches', COLORS.other],
      ['obstacles (truth)', COLORS.truthEdge], ['forecasts: now, +1 s, +2 s', COLORS.forecast], ['static obstacles', COLORS.static],
      ['obstacle regions (forecasts mirrored at their walls)', COLORS.forecast],
      ['global route', COLORS.route], ['goal', COLORS.goal]].filter(function (e) {
      if (e[0].indexOf('obstacle regions') === 0) {
        return C.some(function (c) { return (c.forecasts || []).some(function (f) { return !!f[12]; }); });
      }
      return e[0] !== 'global route' || H.route || C.some(function (c) { return !!c.route; });
    }).forEach(function (e) {
      var li = document.createElement('li'); li.textContent = e[0]; li.style.setProperty('--c', e[1]); legend.appendChild(li);
    });
    var o = D.outcome;
    var hasBranches = C.some(function (c) { return !!c.branches; });
    document.getElementById('summary').textContent =
      o.status + (o.with ? ' with ' + o.with : '') + ' at t = ' + o.t.toFixed(2) + ' s · path ' + o.path_length_m.toFixed(1) +
      ' m · min clearance static ' + o.min_clearance_static_m.toFixed(2) + ' m, moving ' + o.min_clearance_dynamic_m.toFixed(2) +
      ' m · ' + C.length + ' cycles' + (hasBranches ? '' : ' · this log has no branches or forecasts (flown with --no-log-branches)');

    // ---- playback ----
    var slider = document.getElementById('slider'), playBtn = document.getElementById('play');
    var speedSel = document.getElementById('speed'), timeEl = document.getElementById('time');
    var info = document.getElementById('cycle-info');
    slider.min = String(t0); slider.max = String(t1); slider.step = 'any';
    var now = t0, playing = false, lastFrame = null;

    function render(t) {
      now = Math.min(Math.max(t, t0), t1);
      var si = stateIndex(now);
      var u = si + 1 < n ? (now - S.t[si]) / (S.t[si + 1] - S.t[si]) : 0;
      var ci = cycleIndex(now);
      frameViews(interp(S.p, si, u));
      var q = drawView(topView, now, si, u, ci);
      drawView(sideView, now, si, u, ci);
      drawCursor(timeline, timelineBg, now);
      drawCursor(traces, tracesBg, now);
      slider.value = String(now);
      timeEl.textContent = 't = ' + now.toFixed(2) + ' s';
      var c = ci >= 0 ? C[ci] : null;
      var sp = S.speed[si], cl = S.clear[si];
      info.textContent = (c ? 'cycle at ' + c.t.toFixed(2) + ' s: main ' + (c.main === null ? 'none (braking)' : c.main) +
        ', ' + (c.branches ? c.branches.length : '?') + ' branch(es), events: ' + (c.events.join(', ') || '—') : 'before the first cycle') +
        ' · |v| = ' + (finite(sp) ? sp.toFixed(2) : '?') + ' m/s · clearance static ' + (finite(cl[0]) ? cl[0].toFixed(2) : '∞') +
        ' m, moving ' + (finite(cl[1]) ? cl[1].toFixed(2) : '∞') + ' m';
      status.t = now; status.vehicle_px = [+q[0].toFixed(2), +q[1].toFixed(2)];
      status.vehicle = interp(S.p, si, u).map(function (x) { return +x.toFixed(3); });
      status.ready = true;
      writeStatus();
    }
    function setPlaying(p) {
      playing = p; playBtn.textContent = p ? 'Pause' : 'Play'; lastFrame = null;
      if (p) { if (now >= t1) { now = t0; } requestAnimationFrame(tick); }
    }
    function tick(ts) {
      if (!playing) { return; }
      if (lastFrame !== null) { render(now + (ts - lastFrame) / 1000 * parseFloat(speedSel.value)); }
      lastFrame = ts;
      if (now >= t1) { setPlaying(false); return; }
      requestAnimationFrame(tick);
    }
    playBtn.addEventListener('click', function () { setPlaying(!playing); });
    zoomSel.addEventListener('change', function () { render(now); });
    slider.addEventListener('input', function () { setPlaying(false); render(parseFloat(slider.value)); });
    [timeline, traces].forEach(function (cv) {
      cv.addEventListener('click', function (e) {
        var r = cv.getBoundingClientRect();
        setPlaying(false); render(tOf(cv, (e.clientX - r.left) * cv.width / r.width));
      });
    });
    document.addEventListener('keydown', function (e) {
      if (e.target && e.target.tagName === 'SELECT') { return; }
      if (e.key === ' ') { e.preventDefault(); setPlaying(!playing); }
      else if (e.key === 'ArrowRight') { setPlaying(false); render(now + 0.1); }
      else if (e.key === 'ArrowLeft') { setPlaying(false); render(now - 0.1); }
    });

    // `#t=SECONDS` in the address: show that time, paused (through the slider's own handler);
    // otherwise play from the start. `&zoom=80` or `&zoom=30` follows the vehicle.
    var m = /(?:^#|&)t=([0-9.eE+-]+)/.exec(window.location.hash);
    var zm = /(?:^#|&)zoom=([0-9.]+)/.exec(window.location.hash);
    if (zm) { zoomSel.value = zm[1]; }
    render(t0);
    if (m && isFinite(parseFloat(m[1]))) {
      slider.value = m[1];
      slider.dispatchEvent(new Event('input'));
    } else {
      setPlaying(true);
    }
  }

  try { main(); } catch (e) { report('error: ' + (e && e.stack ? e.stack : e)); }
})();

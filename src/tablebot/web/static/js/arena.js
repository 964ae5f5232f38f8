// The arena: the world, the robot (body, bumpers, light cones) and its path coloured by state, on a canvas.
// Shared by the studio and the stand-alone replay file. Plain script: everything hangs on window.TB.
"use strict";
window.TB = window.TB || {};

TB.PALETTE = ["#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#17becf", "#8c564b", "#e377c2", "#7f7f7f",
  "#bcbd22", "#393b79", "#637939", "#8c6d31", "#843c39", "#7b4173", "#3182bd", "#31a354"];
TB.stateColour = (index) => (index === null || index === undefined || index < 0)
  ? "#999999" : TB.PALETTE[index % TB.PALETTE.length];

TB.Arena = class {
  constructor(canvas, onClick) {
    this.canvas = canvas;
    this.ctx = canvas.getContext("2d");
    this.pathLayer = document.createElement("canvas");
    this.world = null;
    this.pose = null;
    this.bumpers = 0;
    this.light = [0, 0];
    this.lastPoint = null;
    this.onClick = onClick;
    this.dirty = true;
    if (onClick) this._listen();
    new ResizeObserver(() => this.resize()).observe(canvas.parentElement);
  }

  setWorld(world) {
    this.world = world;
    this.pose = world ? [world.start[0], world.start[1], world.start[2]] : null;
    this.resize();
  }

  resize() {
    const box = this.canvas.parentElement.getBoundingClientRect();
    const ratio = window.devicePixelRatio || 1;
    const w = Math.max(100, Math.floor(box.width)), h = Math.max(80, Math.floor(box.height));
    this.canvas.width = w * ratio; this.canvas.height = h * ratio;
    this.canvas.style.width = w + "px"; this.canvas.style.height = h + "px";
    this.pathLayer.width = this.canvas.width; this.pathLayer.height = this.canvas.height;
    this.ratio = ratio;
    this._fit();
    this.clearPath();
    if (this.replayPath) this.addPath(this.replayPath);
    this.dirty = true;
    this.draw();
  }

  _fit() {
    if (!this.world) return;
    const xs = this.world.walls.map(p => p[0]), ys = this.world.walls.map(p => p[1]);
    const minX = Math.min(...xs), maxX = Math.max(...xs), minY = Math.min(...ys), maxY = Math.max(...ys);
    const pad = 0.04 * Math.max(maxX - minX, maxY - minY);
    const W = this.canvas.width, H = this.canvas.height;
    this.scale = Math.min(W / (maxX - minX + 2 * pad), H / (maxY - minY + 2 * pad));
    this.ox = (W - (maxX - minX) * this.scale) / 2 - minX * this.scale;
    this.oy = (H + (maxY - minY) * this.scale) / 2 + minY * this.scale;
  }

  toScreen(x, y) { return [this.ox + x * this.scale, this.oy - y * this.scale]; }
  toWorld(px, py) { return [(px - this.ox) / this.scale, (this.oy - py) / this.scale]; }

  clearPath() {
    this.pathLayer.getContext("2d").clearRect(0, 0, this.pathLayer.width, this.pathLayer.height);
    this.lastPoint = null;
    this.dirty = true;
  }

  // points: [[x, y, stateIndex], ...] in metres; drawn once onto the path layer (never redrawn per frame).
  addPath(points) {
    if (!this.world || !points.length) return;
    const g = this.pathLayer.getContext("2d");
    g.lineWidth = 2.2 * this.ratio; g.lineCap = "round"; g.lineJoin = "round";
    let last = this.lastPoint;
    for (const p of points) {
      if (last) {
        const [ax, ay] = this.toScreen(last[0], last[1]), [bx, by] = this.toScreen(p[0], p[1]);
        g.strokeStyle = TB.stateColour(p[2]);
        g.beginPath(); g.moveTo(ax, ay); g.lineTo(bx, by); g.stroke();
      }
      last = p;
    }
    this.lastPoint = last;
    this.dirty = true;
  }

  setRobot(pose, bumpers, light) {
    this.pose = pose; this.bumpers = bumpers || 0; this.light = light || [0, 0];
    this.dirty = true;
  }

  draw() {
    if (!this.dirty) return;
    this.dirty = false;
    const g = this.ctx, W = this.canvas.width, H = this.canvas.height;
    g.setTransform(1, 0, 0, 1, 0, 0);
    g.fillStyle = "#e9ecef"; g.fillRect(0, 0, W, H);
    if (!this.world) return;
    this._drawWorld(g);
    g.drawImage(this.pathLayer, 0, 0);
    if (this.pose && this.pose[0] !== null && this.world.body) this._drawRobot(g);
  }

  _poly(g, pts) {
    g.beginPath();
    pts.forEach((p, i) => { const [x, y] = this.toScreen(p[0], p[1]); i ? g.lineTo(x, y) : g.moveTo(x, y); });
    g.closePath();
  }

  _drawWorld(g) {
    const w = this.world, s = this.scale, r = this.ratio;
    this._poly(g, w.walls); g.fillStyle = "#f6f3ec"; g.fill();
    g.lineWidth = 4 * r; g.strokeStyle = "#2f3640"; g.stroke();
    g.lineJoin = "round"; g.strokeStyle = "#26282b";  // tape on the floor, at its true width
    for (const tape of (w.tape || [])) {
      g.lineWidth = Math.max(1, tape.width * s); g.beginPath();
      tape.points.forEach((p, i) => { const [x, y] = this.toScreen(p[0], p[1]); i ? g.lineTo(x, y) : g.moveTo(x, y); });
      if (tape.closed) g.closePath();
      g.stroke();
    }
    g.fillStyle = "#a4b0be"; g.strokeStyle = "#57606f"; g.lineWidth = 1.5 * r;
    for (const box of w.boxes) { this._poly(g, box); g.fill(); g.stroke(); }
    for (const [x, y, rad] of w.circles) {
      const [cx, cy] = this.toScreen(x, y);
      g.beginPath(); g.arc(cx, cy, rad * s, 0, 2 * Math.PI); g.fill(); g.stroke();
    }
    g.lineWidth = 4 * r; g.strokeStyle = "#2f3640"; g.lineCap = "round";
    for (const [x0, y0, x1, y1] of w.segments) {
      const [a, b] = this.toScreen(x0, y0), [c, d] = this.toScreen(x1, y1);
      g.beginPath(); g.moveTo(a, b); g.lineTo(c, d); g.stroke();
    }
    for (const lamp of w.lamps) {
      const [cx, cy] = this.toScreen(lamp.at[0], lamp.at[1]);
      const reach = Math.sqrt(lamp.intensity) * s;
      const glow = g.createRadialGradient(cx, cy, 0, cx, cy, 0.45 * s);
      glow.addColorStop(0, "rgba(255, 211, 42, 0.55)"); glow.addColorStop(1, "rgba(255, 211, 42, 0)");
      g.fillStyle = glow; g.beginPath(); g.arc(cx, cy, 0.45 * s, 0, 2 * Math.PI); g.fill();
      g.save(); this._poly(g, w.walls); g.clip();  // the ring where a sensor sees the lamp, inside the room
      g.setLineDash([6 * r, 5 * r]); g.strokeStyle = "rgba(184, 134, 11, 0.6)"; g.lineWidth = 1.2 * r;
      g.beginPath(); g.arc(cx, cy, reach, 0, 2 * Math.PI); g.stroke(); g.restore();
      this._star(g, cx, cy, 11 * r);
    }
    // the start pose, as a hollow arrow
    const [sx, sy] = this.toScreen(w.start[0], w.start[1]), h = w.start[2] * Math.PI / 180;
    g.strokeStyle = "#57606f"; g.lineWidth = 1.5 * r; g.setLineDash([3 * r, 3 * r]);
    g.beginPath(); g.arc(sx, sy, 0.06 * s, 0, 2 * Math.PI); g.stroke(); g.setLineDash([]);
    g.beginPath(); g.moveTo(sx, sy); g.lineTo(sx + Math.cos(h) * 0.1 * s, sy - Math.sin(h) * 0.1 * s); g.stroke();
  }

  _star(g, cx, cy, rad) {
    g.beginPath();
    for (let k = 0; k < 10; k++) {
      const a = -Math.PI / 2 + k * Math.PI / 5, rr = k % 2 ? rad * 0.45 : rad;
      g.lineTo(cx + rr * Math.cos(a), cy + rr * Math.sin(a));
    }
    g.closePath(); g.fillStyle = "#ffd32a"; g.fill(); g.strokeStyle = "#b8860b"; g.lineWidth = 1.2 * this.ratio;
    g.stroke();
  }

  _drawRobot(g) {
    const b = this.world.body, L = this.world.light, [x, y, hd] = this.pose, th = hd * Math.PI / 180;
    const c = Math.cos(th), s = Math.sin(th);
    const at = (px, py) => this.toScreen(x + c * px - s * py, y + s * px + c * py);
    const shape = (pts) => { g.beginPath(); pts.forEach((p, i) => { const q = at(p[0], p[1]); i ? g.lineTo(q[0], q[1]) : g.moveTo(q[0], q[1]); }); g.closePath(); };
    const f = b.front, rr = -b.rear, w = b.half_width, ov = b.overlap, t = 0.014;
    // light cones (a robot with phototransistors): brighter when the sensor sees the lamp
    const fov = L ? L.half_response * Math.PI / 180 : 0, toe = L ? L.toe_out * Math.PI / 180 : 0;
    (L ? [[-1, 0], [1, 1]] : []).forEach(([side, k]) => {
      const [cx, cy] = at(L.forward, side * L.sideways);
      const aim = -(th + side * toe), len = 0.25 * this.scale;
      g.fillStyle = this.light[k] >= 1 ? "rgba(255, 200, 0, 0.55)" : "rgba(255, 211, 42, 0.18)";
      g.beginPath(); g.moveTo(cx, cy); g.arc(cx, cy, len, aim - fov, aim + fov); g.closePath(); g.fill();
    });
    shape([[f, -w], [f, w], [rr, w], [rr, -w]]);
    g.fillStyle = "#dfe4ea"; g.fill(); g.strokeStyle = "#2f3640"; g.lineWidth = 1.5 * this.ratio; g.stroke();
    const plates = [[[f, -w], [f, ov], [f - t, ov], [f - t, -w]], [[f, -ov], [f, w], [f - t, w], [f - t, -ov]],
      [[rr, -w], [rr, w], [rr + t, w], [rr + t, -w]]];
    plates.forEach((pts, k) => { shape(pts); g.fillStyle = this.bumpers & (1 << k) ? "#ff3f34" : "#57606f"; g.fill(); });
    const [ax, ay] = at(0, 0), [nx, ny] = at(f * 0.8, 0);
    g.beginPath(); g.moveTo(ax, ay); g.lineTo(nx, ny); g.strokeStyle = "#2f3640"; g.lineWidth = 2 * this.ratio; g.stroke();
  }

  _listen() {
    let down = null;
    this.canvas.addEventListener("pointerdown", (e) => { down = [e.offsetX, e.offsetY]; });
    this.canvas.addEventListener("pointerup", (e) => {
      if (!down || !this.world) return;
      const r = this.ratio, [x, y] = this.toWorld(down[0] * r, down[1] * r);
      const dx = e.offsetX - down[0], dy = down[1] - e.offsetY;
      const heading = Math.hypot(dx, dy) > 12 ? Math.atan2(dy, dx) * 180 / Math.PI : null;
      down = null;
      this.onClick(x, y, heading);
    });
  }
};

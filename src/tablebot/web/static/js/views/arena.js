// The arena: the world, the robot (body, bumpers, light cones, lamps) and its path coloured by state, on a canvas.
// Shared by the studio and the stand-alone replay file.

const WALL = "#2f3640", FLOOR = "#f6f3ec", BLOCK = "#a4b0be", BLOCK_EDGE = "#57606f";
const LAMP_ON = "#ffd32a", LAMP_OFF = "#57606f";

export class Arena {
  constructor(canvas, colourOf, onClick) {
    this.canvas = canvas;
    this.colourOf = colourOf;  // state id -> colour
    this.ctx = canvas.getContext("2d");
    this.pathLayer = document.createElement("canvas");
    this.world = null;
    this.pose = null;
    this.bumpers = 0;
    this.lamps = {};
    this.light = [0, 0];
    this.lastPoint = null;
    this.replayPath = null;
    this.marker = null;  // {x, y, label}: where a counterexample breaks its property
    this.onClick = onClick;
    this.onDrawn = null;  // (ms) => ...: told how long each draw took
    this.dirty = true;
    this.framed = false;  // a frame is asked for
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
    const xs = this.world.walls.map((p) => p[0]), ys = this.world.walls.map((p) => p[1]);
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
    this.invalidate();
  }

  // points: [[x, y, stateId], ...] in metres; drawn once onto the path layer (never redrawn per frame).
  addPath(points) {
    if (!this.world || !points.length) return;
    const g = this.pathLayer.getContext("2d");
    g.lineWidth = 2.2 * this.ratio; g.lineCap = "round"; g.lineJoin = "round";
    let last = this.lastPoint;
    for (const p of points) {
      if (last) {
        const [ax, ay] = this.toScreen(last[0], last[1]), [bx, by] = this.toScreen(p[0], p[1]);
        g.strokeStyle = this.colourOf(p[2]);
        g.beginPath(); g.moveTo(ax, ay); g.lineTo(bx, by); g.stroke();
      }
      last = p;
    }
    this.lastPoint = last;
    this.invalidate();
  }

  /** The robot's pose, bumpers, light sensors and lamps ({L1: 0..8, ...}: off, or on that bright). */
  setRobot(pose, bumpers, light, lamps) {
    this.pose = pose; this.bumpers = bumpers || 0; this.light = light || [0, 0]; this.lamps = lamps || {};
    // what the lamps show, for a person's tools and the tests: "L1=0 L2=8"
    this.canvas.dataset.lamps = Object.entries(this.lamps).map(([name, v]) => `${name}=${v}`).join(" ");
    this.invalidate();
  }

  /** Mark a place (a red ring and a label; null: none), e.g. where a counterexample breaks its property. */
  setMarker(marker) {
    this.marker = marker;
    this.invalidate();
  }

  // Drawn when something in it changed, at the browser's next frame, not at every frame: a page left open
  // all lesson asks nothing of the computer meanwhile (a frame loop that draws nothing took ~6 % of a core in
  // headless Chromium).
  invalidate() {
    this.dirty = true;
    if (this.framed) return;
    this.framed = true;
    requestAnimationFrame(() => {
      this.framed = false;
      const t0 = performance.now();
      this.draw();
      if (this.onDrawn) this.onDrawn(performance.now() - t0);
    });
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
    if (this.marker) this._drawMarker(g, this.marker);
  }

  _drawMarker(g, { x, y, label }) {
    const r = this.ratio, [cx, cy] = this.toScreen(x, y), rad = Math.max(16 * r, 0.14 * this.scale);
    g.lineWidth = 4 * r; g.strokeStyle = "#c0262d"; g.setLineDash([]);
    g.beginPath(); g.arc(cx, cy, rad, 0, 2 * Math.PI); g.stroke();
    g.font = `bold ${Math.round(14 * r)}px system-ui, sans-serif`;
    const w = g.measureText(label).width + 10 * r, h = 20 * r;
    const lx = Math.min(Math.max(4 * r, cx - w / 2), this.canvas.width - w - 4 * r);
    const ly = cy + rad + h + 4 * r < this.canvas.height ? cy + rad + 4 * r : cy - rad - h - 4 * r;
    g.fillStyle = "#c0262d"; g.fillRect(lx, ly, w, h);
    g.fillStyle = "#fff"; g.textBaseline = "middle"; g.fillText(label, lx + 5 * r, ly + h / 2);
  }

  // --- the world -----------------------------------------------------------------------------------------

  _line(g, pts, closed) {
    g.beginPath();
    pts.forEach((p, i) => { const [x, y] = this.toScreen(p[0], p[1]); if (i) g.lineTo(x, y); else g.moveTo(x, y); });
    if (closed) g.closePath();
  }

  _drawWorld(g) {
    const w = this.world;
    this._line(g, w.walls, true); g.fillStyle = FLOOR; g.fill();
    g.lineWidth = 4 * this.ratio; g.strokeStyle = WALL; g.stroke();
    this._drawTape(g, w.tape || []);
    this._drawObstacles(g, w);
    for (const lamp of w.lamps) this._drawLamp(g, lamp);
    this._drawStart(g, w.start);
  }

  // tape on the floor, at its true width
  _drawTape(g, tapes) {
    g.lineJoin = "round"; g.strokeStyle = "#26282b";
    for (const tape of tapes) {
      g.lineWidth = Math.max(1, tape.width * this.scale);
      this._line(g, tape.points, tape.closed);
      g.stroke();
    }
  }

  _drawObstacles(g, w) {
    g.fillStyle = BLOCK; g.strokeStyle = BLOCK_EDGE; g.lineWidth = 1.5 * this.ratio;
    for (const box of w.boxes) { this._line(g, box, true); g.fill(); g.stroke(); }
    for (const [x, y, rad] of w.circles) {
      const [cx, cy] = this.toScreen(x, y);
      g.beginPath(); g.arc(cx, cy, rad * this.scale, 0, 2 * Math.PI); g.fill(); g.stroke();
    }
    g.lineWidth = 4 * this.ratio; g.strokeStyle = WALL; g.lineCap = "round";
    for (const [x0, y0, x1, y1] of w.segments) { this._line(g, [[x0, y0], [x1, y1]], false); g.stroke(); }
  }

  _drawLamp(g, lamp) {
    const s = this.scale, r = this.ratio, [cx, cy] = this.toScreen(lamp.at[0], lamp.at[1]);
    const glow = g.createRadialGradient(cx, cy, 0, cx, cy, 0.45 * s);
    glow.addColorStop(0, "rgba(255, 211, 42, 0.55)"); glow.addColorStop(1, "rgba(255, 211, 42, 0)");
    g.fillStyle = glow; g.beginPath(); g.arc(cx, cy, 0.45 * s, 0, 2 * Math.PI); g.fill();
    g.save(); this._line(g, this.world.walls, true); g.clip();  // where a sensor sees the lamp, inside the room
    g.setLineDash([6 * r, 5 * r]); g.strokeStyle = "rgba(184, 134, 11, 0.6)"; g.lineWidth = 1.2 * r;
    g.beginPath(); g.arc(cx, cy, Math.sqrt(lamp.intensity) * s, 0, 2 * Math.PI); g.stroke(); g.restore();
    this._star(g, cx, cy, 11 * r);
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

  // the start pose, as a hollow arrow
  _drawStart(g, start) {
    const s = this.scale, r = this.ratio, [sx, sy] = this.toScreen(start[0], start[1]), h = start[2] * Math.PI / 180;
    g.strokeStyle = BLOCK_EDGE; g.lineWidth = 1.5 * r; g.setLineDash([3 * r, 3 * r]);
    g.beginPath(); g.arc(sx, sy, 0.06 * s, 0, 2 * Math.PI); g.stroke(); g.setLineDash([]);
    g.beginPath(); g.moveTo(sx, sy); g.lineTo(sx + Math.cos(h) * 0.1 * s, sy - Math.sin(h) * 0.1 * s); g.stroke();
  }

  // --- the robot -----------------------------------------------------------------------------------------

  // A function from robot coordinates (metres, x forward) to the screen.
  _body() {
    const [x, y, hd] = this.pose, th = hd * Math.PI / 180, c = Math.cos(th), s = Math.sin(th);
    return { th, at: (px, py) => this.toScreen(x + c * px - s * py, y + s * px + c * py) };
  }

  _shape(g, at, pts) {
    g.beginPath();
    pts.forEach((p, i) => { const q = at(p[0], p[1]); if (i) g.lineTo(q[0], q[1]); else g.moveTo(q[0], q[1]); });
    g.closePath();
  }

  _drawRobot(g) {
    const b = this.world.body, { th, at } = this._body();
    if (this.world.light) this._drawCones(g, at, th);
    const f = b.front, rr = -b.rear, w = b.half_width, ov = b.overlap, t = 0.014;
    this._shape(g, at, [[f, -w], [f, w], [rr, w], [rr, -w]]);
    g.fillStyle = "#dfe4ea"; g.fill(); g.strokeStyle = WALL; g.lineWidth = 1.5 * this.ratio; g.stroke();
    const plates = [[[f, -w], [f, ov], [f - t, ov], [f - t, -w]], [[f, -ov], [f, w], [f - t, w], [f - t, -ov]],
      [[rr, -w], [rr, w], [rr + t, w], [rr + t, -w]]];
    plates.forEach((pts, k) => {
      this._shape(g, at, pts); g.fillStyle = this.bumpers & (1 << k) ? "#ff3f34" : BLOCK_EDGE; g.fill();
    });
    const [ax, ay] = at(0, 0), [nx, ny] = at(f * 0.8, 0);
    g.beginPath(); g.moveTo(ax, ay); g.lineTo(nx, ny); g.strokeStyle = WALL; g.lineWidth = 2 * this.ratio; g.stroke();
    this._drawLamps(g, at, rr, w);
  }

  // the lamps on the robot's back, the first on the left (as [lamps] lists them): lit yellow while on
  _drawLamps(g, at, rr, w) {
    const names = Object.keys(this.lamps || {}), rad = Math.max(5 * this.ratio, 0.02 * this.scale);
    names.forEach((name, i) => {
      const [cx, cy] = at(rr * 0.55, w * (1 - 2 * (i + 1) / (names.length + 1))), on = this.lamps[name] > 0;
      if (on) { g.fillStyle = "rgba(255, 211, 42, 0.45)"; g.beginPath(); g.arc(cx, cy, rad * 2, 0, 2 * Math.PI); g.fill(); }
      g.fillStyle = on ? LAMP_ON : LAMP_OFF; g.strokeStyle = WALL; g.lineWidth = this.ratio;
      g.beginPath(); g.arc(cx, cy, rad, 0, 2 * Math.PI); g.fill(); g.stroke();
    });
  }

  // light cones (a robot with phototransistors): brighter when the sensor sees the lamp
  _drawCones(g, at, th) {
    const L = this.world.light, fov = L.half_response * Math.PI / 180, toe = L.toe_out * Math.PI / 180;
    for (const [side, k] of [[-1, 0], [1, 1]]) {
      const [cx, cy] = at(L.forward, side * L.sideways), aim = -(th + side * toe), len = 0.25 * this.scale;
      g.fillStyle = this.light[k] >= 1 ? "rgba(255, 200, 0, 0.55)" : "rgba(255, 211, 42, 0.18)";
      g.beginPath(); g.moveTo(cx, cy); g.arc(cx, cy, len, aim - fov, aim + fov); g.closePath(); g.fill();
    }
  }

  // A click moves (start pose or lamp); a drag also aims the start.
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
}

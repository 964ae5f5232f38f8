// The trace player: a trace's columns (tick, event, row, state, timer, outputs, pose...) scrubbed and
// played through the same views as the live robot: arena, grid, diagram, timeline and the status line.
"use strict";
window.TB = window.TB || {};

TB.describeTick = function (machine, t) {
  // t: {tick, state, timer, event, row, outputs: {name: value}} -> a line a person reads
  const parts = [`tick ${t.tick}`, `${(t.tick * machine.tick_ms / 1000).toFixed(2)} s`];
  const st = machine.states.find(s => s.id === String(t.state));
  parts.push(`state ${t.state}` + (st && st.label ? ` (${st.label})` : ""));
  if (t.timer !== undefined && t.timer !== null) parts.push(`timer ${t.timer} (${(t.timer * machine.tick_ms / 1000).toFixed(2)} s)`);
  parts.push(t.row === null || t.row === undefined || t.row < 0 ? "no row fired" : `row ${t.row + 1} fired`);
  if (t.event !== undefined && t.event !== null) {
    const names = machine.events.filter((e, i) => t.event & (1 << (machine.events.length - 1 - i)));
    parts.push("events: " + (names.join(" + ") || "none"));
  }
  if (t.outputs) parts.push(Object.entries(t.outputs).map(([k, v]) => `${k} ${v}`).join(" "));
  return parts.join(" · ");
};

TB.Player = class {
  constructor(views) {
    this.views = views;  // {arena, grid, diagram, timeline, status, slider, clock, stateCol()}
    this.columns = null;
    this.n = 0;
    this.index = 0;
    this.playing = false;
    this.speed = 1;
    this._frame = this._frame.bind(this);
  }

  load(columns, machine, atTick) {
    this.columns = columns;
    this.machine = machine;
    this.n = columns.tick.length;
    const ids = machine.states.map(s => s.id);
    this.stateIndex = columns.state.map(s => ids.indexOf(String(s)));
    this.outputNames = machine.outputs.filter(name => name in columns);
    this.lightKeys = Object.keys(columns).filter(k => k.endsWith("_light"));  // right, then left
    this.views.timeline.setStates(this.stateIndex);
    this.views.slider.max = Math.max(0, this.n - 1);
    const arena = this.views.arena;
    if (arena && "x" in columns) {
      const pts = [];
      let last = null;
      for (let i = 0; i < this.n; i++) {
        const x = columns.x[i], y = columns.y[i], s = this.stateIndex[i];
        if (x === null || y === null) continue;
        if (!last || last[2] !== s || Math.hypot(x - last[0], y - last[1]) > 0.005) { last = [x, y, s]; pts.push(last); }
      }
      arena.replayPath = pts;
      arena.clearPath();
      arena.addPath(pts);
    }
    this.seek(atTick ? Math.min(atTick, this.n - 1) : 0);
  }

  tickAt(i) {
    const c = this.columns, outputs = {};
    for (const name of this.outputNames) outputs[name] = c[name][i];
    return { tick: c.tick[i], state: c.state[i], timer: c.timer ? c.timer[i] : null, event: c.event ? c.event[i] : null,
      row: c.row ? c.row[i] : null, outputs };
  }

  seek(i) {
    if (!this.n) return;
    this.index = Math.max(0, Math.min(this.n - 1, i));
    const c = this.columns, t = this.tickAt(this.index), v = this.views;
    v.slider.value = this.index;
    v.timeline.setCursor(this.index);
    v.status.textContent = TB.describeTick(this.machine, t);
    v.diagram.highlight(String(t.state));
    v.grid.setLive(t.row === null ? -1 : t.row, String(t.state), v.stateCol());
    if (v.arena && "x" in c && c.x[this.index] !== null) {
      const bumpers = c.bumpers ? c.bumpers[this.index] : 0;
      const light = this.lightKeys.map(k => c[k][this.index]);
      v.arena.setRobot([c.x[this.index], c.y[this.index], c.heading[this.index]], bumpers, light);
    }
    if (v.onSeek) v.onSeek(t, this.index);
  }

  play(speed) {
    this.speed = speed || this.speed;
    if (this.index >= this.n - 1) this.seek(0);
    this.playing = true;
    this.started = performance.now();
    this.from = this.index;
    requestAnimationFrame(this._frame);
  }

  pause() { this.playing = false; }

  _frame(now) {
    if (!this.playing) return;
    const ticks = this.speed === 0 ? 40 * (now - this.started) : (now - this.started) / this.machine.tick_ms * this.speed;
    const i = this.from + Math.floor(ticks);
    this.seek(i);
    if (i >= this.n - 1) { this.playing = false; if (this.views.onEnd) this.views.onEnd(); return; }
    requestAnimationFrame(this._frame);
  }
};

// The trace player's buttons (play/pause, scrub, speed) and the page's A−/A+ zoom, wired the same way on
// the studio and on a replay page.
TB.wirePlayerControls = function ($, player) {
  $("tplay").addEventListener("click", () => {
    if (player.playing) { player.pause(); $("tplay").textContent = "▶ Play"; } else { player.play(); $("tplay").textContent = "❚❚ Pause"; }
  });
  $("scrub").addEventListener("input", (e) => player.seek(+e.target.value));
  document.querySelectorAll("[data-tspeed]").forEach(b => b.addEventListener("click", () => {
    player.speed = +b.dataset.tspeed;
    if (player.playing) player.play(player.speed);
    document.querySelectorAll("[data-tspeed]").forEach(o => o.classList.toggle("on", o === b));
  }));
};

TB.wireZoom = function ($, arena) {
  let zoom = 1;
  const setZoom = (z) => { zoom = Math.max(0.8, Math.min(1.6, z)); document.documentElement.style.setProperty("--zoom", zoom); arena.resize(); };
  $("smaller").addEventListener("click", () => setZoom(zoom - 0.1));
  $("bigger").addEventListener("click", () => setZoom(zoom + 0.1));
};

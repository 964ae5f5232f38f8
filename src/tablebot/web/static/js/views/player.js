// The trace player: a trace's columns (tick, event, row, state, timer, outputs, pose...) scrubbed and
// played through the same views as the live robot: arena, grid, diagram, timeline and the status line.
import { all, byId } from "../lib/dom.js";
import { number, t as word } from "../lib/words.js";

// two decimals always, so the status line does not jump while a trace plays (1,80 s then 1,81 s)
const seconds = (ticks, machine) => number(ticks * machine.tick_ms / 1000, 2, 2) + " s";

/** One tick as a line a person reads; t: {tick, state, timer, event, row, outputs: {name: value}}. */
export function describeTick(machine, t) {
  const parts = [word("tick.tick", { tick: t.tick }), seconds(t.tick, machine)];
  const st = machine.states.find((s) => s.id === String(t.state));
  parts.push(word("tick.state", { state: t.state }) + (st && st.label ? ` (${st.label})` : ""));
  if (t.timer !== undefined && t.timer !== null) parts.push(word("tick.timer", { timer: t.timer, seconds: seconds(t.timer, machine) }));
  parts.push(fired(machine, t.row));
  if (t.event !== undefined && t.event !== null) {
    const names = machine.events.filter((e, i) => t.event & (1 << (machine.events.length - 1 - i)));
    parts.push(word("tick.events", { names: names.join(" + ") || word("tick.no_events") }));
  }
  if (t.outputs) parts.push(Object.entries(t.outputs).map(([k, v]) => `${k} ${v}`).join(" "));
  for (const o of t.others || []) parts.push(otherTable(machine, o));
  return parts.join(" · ");
}

// a person reads the file's line numbers (the grid's); a trace's 0-based row is an index into the rows
const fired = (machine, row) => (row === null || row === undefined || row < 0 ? word("tick.none") :
  word("tick.fired", { line: machine.row_lines[row] }));

/** Another table of the robot on this tick (a trace's NAME.state and NAME.row): its state and the line that fired. */
function otherTable(machine, { name, state, row }) {
  const line = row === null || row === undefined || row < 0 ? null : ((machine.table_lines || {})[name] || {})[row];
  if (line === null) return word("tick.other_none", { table: name, state });
  return word("tick.other", { table: name, state, line: line === undefined ? "?" : line });
}

/** The robot's tables a trace has besides its main one (its NAME.state columns), in its order. */
const otherTables = (columns) => Object.keys(columns).filter((k) => k.endsWith(".state")).map((k) => k.slice(0, -6));

/** The path a trace drew: a point every 5 mm or at a state change, [x, y, stateId]. */
function tracePath(columns, stateIds) {
  const pts = [];
  let last = null;
  for (let i = 0; i < columns.tick.length; i++) {
    const x = columns.x[i], y = columns.y[i], s = stateIds[i];
    if (x === null || y === null) continue;
    if (!last || last[2] !== s || Math.hypot(x - last[0], y - last[1]) > 0.005) { last = [x, y, s]; pts.push(last); }
  }
  return pts;
}

export class Player {
  constructor(views) {
    this.views = views;  // {arena, grid, diagram, timeline, status, slider, stateCol(), onEnd(), onSeek(t)}
    this.columns = null;
    this.n = 0;
    this.index = 0;
    this.playing = false;
    this.speed = 1;
    this._frame = this._frame.bind(this);
  }

  load(columns, machine, atTick) {
    this.columns = columns;
    this.n = columns.tick.length;
    this.lightKeys = Object.keys(columns).filter((k) => k.endsWith("_light"));  // right, then left
    this.views.slider.max = Math.max(0, this.n - 1);
    this._speaking(machine);
    this.seek(atTick ? Math.min(atTick, this.n - 1) : 0);
  }

  /** Another table's tab shown (or the table edited): the same trace, at the same tick and playing on, with
   * ``machine``'s table speaking. */
  show(machine) {
    if (!this.columns || !machine || machine === this.machine) return;
    this._speaking(machine);
    this.seek(this.index);
  }

  // A robot of several tables: the table whose tab is shown speaks (its state, row and timer; its states
  // colour the timeline and the path), the others are said beside it (the main table's own columns are
  // state, row, timer and event)
  _speaking(machine) {
    const columns = this.columns;
    this.machine = machine;
    this.others = otherTables(columns);
    this.view = this.others.includes(machine.name) ? machine.name : null;
    if (this.view) this.others = [machine.main_name, ...this.others.filter((n) => n !== this.view)];
    this.stateIds = this.column("state").map(String);
    this.outputNames = machine.outputs.filter((name) => name in columns);
    this.views.timeline.setStates(this.stateIds);
    const arena = this.views.arena;
    if (arena && "x" in columns) {
      arena.replayPath = tracePath(columns, this.stateIds);
      arena.clearPath();
      arena.addPath(arena.replayPath);
    }
  }

  /** The column ``key`` (state, row, timer, event) of the table shown: ``lights.state`` for the lights tab. */
  column(key, table = this.view) {
    return this.columns[table && table !== this.machine.main_name ? `${table}.${key}` : key];
  }

  tickAt(i) {
    const c = this.columns, outputs = {};
    for (const name of this.outputNames) outputs[name] = c[name][i];
    const at = (key, table) => { const col = this.column(key, table); return col ? col[i] : null; };
    const others = this.others.map((name) => ({ name, state: at("state", name), row: at("row", name) }));
    return { tick: c.tick[i], state: at("state"), timer: at("timer"), event: at("event"), row: this._row(at("row")),
      outputs, others };
  }

  // A row as the grid counts them (the rows as run): a trace names its row as written (a group's row once),
  // which is the first of the rows as run on its line
  _row(row) {
    if (row === null || row === undefined || row < 0) return row;
    const written = this.view ? (this.machine.table_lines || {})[this.view] : this.machine.written_lines;
    return written ? this.machine.row_lines.indexOf(written[row]) : row;
  }

  seek(i) {
    if (!this.n) return;
    this.index = Math.max(0, Math.min(this.n - 1, i));
    const t = this.tickAt(this.index), v = this.views;
    v.slider.value = this.index;
    v.timeline.setCursor(this.index);
    v.status.textContent = describeTick(this.machine, t);
    v.diagram.highlight(String(t.state));
    v.grid.setLive(t.row === null ? -1 : t.row, String(t.state), v.stateCol());
    this._pose();
    if (v.onSeek) v.onSeek(t, this.index);
  }

  _pose() {
    const c = this.columns, i = this.index, arena = this.views.arena;
    if (!arena || !("x" in c) || c.x[i] === null) return;
    const lamps = Object.fromEntries((this.machine.lamps || []).filter((n) => n in c).map((n) => [n, c[n][i]]));
    arena.setRobot([c.x[i], c.y[i], c.heading[i]], c.bumpers ? c.bumpers[i] : 0, this.lightKeys.map((k) => c[k][i]), lamps);
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
    const ms = now - this.started;
    const ticks = this.speed === 0 ? 40 * ms : ms / this.machine.tick_ms * this.speed;
    const i = this.from + Math.floor(ticks);
    this.seek(i);
    if (i >= this.n - 1) { this.playing = false; if (this.views.onEnd) this.views.onEnd(); return; }
    requestAnimationFrame(this._frame);
  }
}

/** The trace player's buttons (play/pause, scrub, speed), wired the same on the studio and a replay page. */
export function wirePlayerControls(player) {
  byId("tplay").addEventListener("click", () => {
    if (player.playing) player.pause(); else player.play();
    byId("tplay").textContent = word(player.playing ? "live.pause" : "live.play");
  });
  byId("scrub").addEventListener("input", (e) => player.seek(+e.target.value));
  for (const b of all("[data-tspeed]")) {
    b.addEventListener("click", () => {
      player.speed = +b.dataset.tspeed;
      if (player.playing) player.play(player.speed);
      for (const o of all("[data-tspeed]")) o.classList.toggle("on", o === b);
    });
  }
}

/** The page's A−/A+ zoom. */
export function wireZoom(arena) {
  let zoom = 1;
  const setZoom = (z) => {
    zoom = Math.max(0.8, Math.min(1.6, z));
    document.documentElement.style.setProperty("--zoom", zoom);
    arena.resize();
  };
  byId("smaller").addEventListener("click", () => setZoom(zoom - 0.1));
  byId("bigger").addEventListener("click", () => setZoom(zoom + 0.1));
}

// What the page does with each message from the server: mostly a change of state (the panels subscribed
// to it redraw), sometimes a view's own content (the grid's rows, the diagram's SVG, a trace to play).
import { addOption, byId } from "../lib/dom.js";
import { banner } from "./banner.js";
import { stats } from "./stats.js";

/** The note over the arena (a world problem, a trace without poses); "" hides it. */
export function arenaNote(text) {
  const note = byId("arena-note");
  note.textContent = text;
  note.hidden = !text;
}

const controlState = (m) => ({ paused: m.paused, speed: m.speed, held: m.held || {}, runError: m.error || null });

function analysis(store, m) {
  const { seq, editSent, machine } = store.get();
  if (m.seq !== null && m.seq !== seq) return;  // an answer to an older edit
  if (m.seq !== null && editSent) stats.analysisMs.push(performance.now() - editSent);
  store.set({ analysis: m, machine: m.machine || machine, mask: undefined, ...(m.seq !== null ? { dirty: m.dirty } : {}) });
}

function arena(store, views, m) {
  store.set({ arenaOk: m.ok });
  if (!m.ok) { arenaNote(m.problem); return; }
  arenaNote("");
  views.arena.replayPath = null;
  views.arena.setWorld(m.world);
  byId("seed").value = m.settings.seed;
  byId("battery").value = Math.round(100 * m.settings.charge);
  byId("battery-text").textContent = Math.round(100 * m.settings.charge) + "%";
  store.set({ world: m.world, tickMs: m.tick_ms, frame: null, ...controlState(m) });
}

function frame(store, m) {
  stats.frames += 1; stats.ticks = m.tick; stats.lastTick = m.tick;
  store.set({ frame: m, ...controlState(m) });
}

function trace(store, views, m) {
  store.set({ mode: "trace" });
  addOption(byId("trace-pick"), m.name);
  byId("trace-pick").value = m.name;
  const machine = store.get().machine;
  if (!machine) { banner("open a table that reads before playing a trace", "bad"); return; }
  views.player.load(m.columns, machine, m.at_tick);
  store.set({ why: [] });
  arenaNote("x" in m.columns ? "" : "this trace has no robot pose (a replay, a counterexample or a real robot): "
    + "the table, the diagram and the timeline follow it; the arena cannot");
}

function conflict(store, send, m) {
  banner(m.message + " — " + m.hint, "bad", [["Reload", () => send({ op: "open", path: store.get().path })],
    ["Save anyway", () => send({ op: "save", force: true })]]);
}

/** The handlers, by message type. */
export function messageHandlers(store, views, send) {
  return {
    table(m) {
      views.grid.setTable(m.header, m.grid, m.lines);
      store.set({ path: m.path, dirty: false });
    },
    grid(m) { views.grid.setTable(views.grid.header, m.grid, views.grid.lines); },
    analysis: (m) => analysis(store, m),
    diagram(m) {
      views.diagram.setSvg(m.svg);
      const current = store.get().frame;
      if (current) views.diagram.highlight(current.state_id);
    },
    arena: (m) => arena(store, views, m),
    control: (m) => store.set(controlState(m)),
    frame: (m) => frame(store, m),
    trace: (m) => trace(store, views, m),
    files: (m) => store.set({ files: m }),
    saved(m) {
      store.set({ dirty: false });
      banner(`saved ${m.path} (the previous version is ${m.backup})`, "good");
    },
    conflict: (m) => conflict(store, send, m),
    notice: (m) => banner(m.message, "good"),
    error: (m) => banner(m.message, "bad"),
  };
}

// What the page does with each message from the server: mostly a change of state (the panels subscribed
// to it redraw), sometimes a view's own content (the grid's rows, the diagram's SVG, a trace to play).
import { addOption, byId } from "../lib/dom.js";
import { clock, percent, t } from "../lib/words.js";
import { ask } from "./ask.js";
import { banner } from "./banner.js";
import { byKind } from "./protocol.js";
import { showShared } from "./sharebox.js";
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
  views.arena.setMarker(null);
  if ((store.get().cex || {}).shown) store.set({ cex: null });  // started over after a counterexample
  views.arena.replayPath = null;
  views.arena.setWorld(m.world);
  byId("seed").value = m.settings.seed;
  byId("battery").value = Math.round(100 * m.settings.charge);
  byId("battery-text").textContent = percent(m.settings.charge);
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
  if (!machine) { banner(t("trace.no_table"), "bad"); return; }
  views.player.load(m.columns, machine, m.at_tick);
  store.set({ why: [] });
  arenaNote("x" in m.columns ? "" : t("trace.no_pose"));
}

const WHAT = {  // how the file changed: the dialog's title, and what it means (keys of the page's catalog)
  changed: ["conflict.changed", "conflict.changed_why"],
  replaced: ["conflict.replaced", "conflict.replaced_why"],
  deleted: ["conflict.deleted", "conflict.deleted_why"],
  "saved in another tab": ["conflict.other_tab", "conflict.other_tab_why"],
};

// The file on disk is not the one the draft started from: save mine over theirs (kept as NAME.bak), or
// load theirs (mine dropped). Asked at once when a save lost; a notice when another tab saved meanwhile.
function conflict(store, send, drafts, m) {
  const saveMine = () => send({ op: "save", force: m.theirs });
  const loadTheirs = () => { drafts.drop(m.path, true); store.set({ offerDraft: null }); send({ op: "open", path: m.path }); };
  const answers = m.how === "deleted" ? [[t("conflict.save_again"), saveMine, "primary"]] :
    [[t("conflict.save_mine", { backup: m.backup }), saveMine, "primary"], [t("conflict.load_theirs"), loadTheirs]];
  if (m.op !== "save") {  // another tab saved while this one was editing: said, not asked
    banner(t("conflict.kept", { message: m.message }), "bad", answers.map(([label, action]) => [label, action]));
    return;
  }
  const later = () => banner(t("conflict.later_said"), "bad");
  const [title, why] = WHAT[m.how] || WHAT.changed;
  ask(t(title, { path: m.path }), [t(why) + " " + t("conflict.nothing_saved"),
      m.how === "deleted" ? t("conflict.deleted_answer") : t("conflict.answer", { backup: m.backup })],
    [...answers, [t("conflict.later"), later]], later);
}

// Edits this browser kept for the table just opened, which its server session does not have (the page was
// reloaded, or its connection dropped): put them back, or drop them.
function offerDraft(store, send, drafts, m) {
  const draft = drafts.waiting(m.path, m.header, m.grid);
  if (!draft) return;
  const restore = () => {
    const seq = store.get().seq + 1;
    store.set({ seq, version: draft.base });  // the draft's own start, kept with it at every edit
    send({ op: "restore", base: draft.base, header: draft.header, grid: draft.grid, seq });
  };
  ask(t("draft.title", { path: m.path }), [t("draft.why", { path: m.path, at: clock(draft.at) }),
    draft.base !== m.version ? t("draft.changed", { path: m.path }) : ""],
  [[t("draft.restore"), restore, "primary"], [t("draft.drop"), () => drafts.drop(m.path, true)]]);
}

// A table from the server (opened, reloaded, connected again): the draft kept of it is offered when the page
// asked for it (not when another tab's save reloaded it).
function table(store, views, send, drafts, m) {
  views.grid.setTable(m.header, m.grid, m.lines, m.columns, m.tick_ms);  // drawn once: its columns come with it
  const offer = store.get().offerDraft === m.path;
  store.set({ path: m.path, dirty: Boolean(m.dirty), version: m.version, offerDraft: null });
  if (offer) offerDraft(store, send, drafts, m);
}

/** The handlers, by message type: one for each kind of message the protocol has (protocol.js). */
export function messageHandlers(store, views, send, drafts) {
  return byKind({
    table: (m) => table(store, views, send, drafts, m),
    grid(m) {
      views.grid.setTable(views.grid.header, m.grid, m.lines || views.grid.lines);
      drafts.keep();
    },
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
      store.set({ dirty: false, version: m.version });
      drafts.drop(m.path);
      banner(m.backup ? t("saved.backup", { path: m.path, backup: m.backup }) : t("saved.saved", { path: m.path }), "good");
    },
    conflict: (m) => conflict(store, send, drafts, m),
    notice: (m) => banner(m.message, "good"),
    error: (m) => banner(m.message, "bad"),
    shared: (m) => showShared(m),
  });
}

// The parts of the page drawn from the store: each function subscribes to the keys it shows.
import { addOption, all, button, byId, make } from "../lib/dom.js";
import { number, t } from "../lib/words.js";
import { describeTick } from "../views/player.js";
import { banner } from "./banner.js";
import { arenaNote } from "./messages.js";
import { stateColumn } from "./views.js";

const counted = (word, n) => t(n === 1 ? `counts.${word}` : `counts.${word}s`, { n });

function countsText(m) {
  const c = m.counts || {};
  const n = m.diagnostics.length;
  if (!m.ok) return [t(n === 1 ? "counts.problem" : "counts.problems", { n }), "bad"];
  const text = t("counts.ok", { rows: counted("row", m.machine.rows), states: counted("state", m.machine.states.length),
    errors: counted("error", c.error || 0), warnings: counted("warning", c.warning || 0) });
  return [text, c.error ? "bad" : c.warning ? "warn" : "good"];
}

// The checks of the latest edit: on the grid's cells and rows, in the checks panel and the toolbar.
function showAnalysis(store, views) {
  store.on(["analysis"], ({ analysis: m, machine, tickMs }) => {
    views.grid.lines = m.lines;
    if (m.machine) views.grid.rowLines = m.machine.row_lines;  // else the last table that read: the one running
    views.grid.setColumns(m.columns, m.machine ? m.machine.tick_ms : (machine ? machine.tick_ms : tickMs));
    views.grid.setDiagnostics(m.diagnostics);
    views.grid.setFindings(m.findings || []);
    views.checks.render(m);
    const [text, kind] = countsText(m);
    byId("counts").textContent = text;
    byId("counts").className = "counts " + kind;
    byId("analysis-time").textContent = t("counts.checked", { ms: number(m.ms, 1) });
  });
  // the robot keeps running the table it was started with: while the edited one does not read, say so
  store.on(["analysis", "arenaOk", "mode"], ({ analysis, arenaOk, mode }) => {
    const stale = Boolean(analysis && !analysis.ok && arenaOk && mode === "live");
    byId("arena-stale").hidden = !stale;
    byId("arena-stale").textContent = stale ? t("arena.stale") : "";
  });
}

// The live robot: arena, lit row and state, status line, why the rows fired.
function showFrames(store, views) {
  store.on(["frame"], ({ frame: m, mode, machine }) => {
    if (!m || mode !== "live") return;
    views.arena.addPath(m.path);
    views.arena.setRobot(m.pose, m.bumpers, m.light, m.lamps);
    byId("arena").dataset.tick = m.tick;  // the tick the arena shows (its lamps: data-lamps)
    const row = m.fired.length ? m.fired[m.fired.length - 1][1] : (m.paused ? m.row : views.grid.liveRow);
    views.grid.setLive(row, m.state_id, stateColumn(store));
    views.diagram.highlight(m.state_id);
    const outputs = {};
    (machine ? machine.outputs : []).forEach((name, i) => { outputs[name] = m.outputs[i]; });
    if (machine) {
      byId("status").textContent = describeTick(machine, { tick: m.tick, state: m.state_id, timer: m.timer,
        event: m.event, row: m.row, outputs });
    }
    showCounterexample(store, views, m);
    const why = m.why || [];  // repeated in every frame while paused: redrawn only when it says something new
    store.set({ mask: m.mask, ...(JSON.stringify(why) === JSON.stringify(store.get().why) ? {} : { why }) });
  });
}

// A counterexample playing in the arena: once its scripted inputs are spent and the run paused on its last
// tick, the place is marked and the property's words said; Play (or Reset) goes on without them.
function showCounterexample(store, views, m) {
  const { cex } = store.get();
  if (!cex) return;
  if (m.paused && m.scripted === 0 && m.pose[0] !== null) {
    const what = cex.example ? "reached" : "broken";
    views.arena.setMarker({ x: m.pose[0], y: m.pose[1], label: t(`cex.${what}_marker`, { name: cex.name }) });
    arenaNote(`${cex.example ? "✔" : "✘"} ` + t(`cex.${what}_note`, { name: cex.name, tick: m.tick, text: cex.text }));
    cex.shown = true;
  } else if (cex.shown && !m.paused) {
    views.arena.setMarker(null);
    arenaNote("");
    store.set({ cex: null });
  }
}

function showWhy(store, views) {
  store.on(["why"], ({ why }) => {
    byId("why").replaceChildren(...why.map((item) => {
      const li = make("li", { className: "why-" + item.status }, item.why);
      if (item.row !== null) li.addEventListener("click", () => views.grid.select([views.grid.gridRow(item.row)]));
      return li;
    }));
  });
}

const HELD_WORDS = { true: "inputs.held_on", false: "inputs.held_off" };
const HELD_CLASSES = { true: " held-on", false: " held-off" };

function inputButton(store, send, name) {
  const b = make("button", { type: "button" });
  b.dataset.input = name;
  b.addEventListener("click", () => {  // on, then off, then the sensor decides again
    const held = store.get().held[name];
    send({ op: "sim", action: "hold", input: name, on: held === undefined ? true : held === true ? false : null });
  });
  return b;
}

function paintInputs(buttons, { machine, held, mode, mask }) {
  for (const [name, b] of buttons) {
    const live = mask !== undefined && (mask & machine.input_bits[name]);
    b.className = "input" + (live ? " live" : "") + (HELD_CLASSES[held[name]] || "");
    b.textContent = name + (HELD_WORDS[held[name]] ? t(HELD_WORDS[held[name]]) : "");
    b.disabled = mode !== "live";
    b.title = t("inputs.title", { name: machine.labels[name] || name });
  }
}

// The robot's inputs: lit when on, held on or off by hand while the robot is live. The buttons are made
// once per machine and repainted in place (a button that is clicked must not be replaced meanwhile).
function showInputs(store, send) {
  let buttons = new Map();
  store.on(["machine"], ({ machine }) => {
    buttons = new Map((machine ? machine.inputs : []).map((name) => [name, inputButton(store, send, name)]));
    byId("inputs").replaceChildren(...buttons.values());
  });
  store.on(["machine", "held", "mode", "mask"], (state) => { if (state.machine) paintInputs(buttons, state); });
}

function showControls(store) {
  store.on(["paused", "speed"], ({ paused, speed }) => {
    byId("play").textContent = paused ? t("live.play") : t("live.pause");
    byId("step").disabled = !paused;
    for (const b of all("[data-speed]")) b.classList.toggle("on", b.dataset.speed === speed);
  });
  store.on(["arenaOk"], ({ arenaOk }) => { byId("play").disabled = !arenaOk; });
  store.on(["runError"], ({ runError }) => { if (runError) banner(t("live.stopped", { error: runError }), "bad"); });
  store.on(["clickMode"], ({ clickMode }) => {
    for (const b of all("[data-click]")) b.classList.toggle("on", b.dataset.click === clickMode);
  });
}

/** A folder without a table: the page says so, and offers `tablebot new`'s templates (a click makes the robot
 * in a new folder here and opens it; the commands do the same in a terminal). */
export function showNoTable(config, send) {
  const what = make("p", {}, config.folder ? t("none.what", { folder: config.folder }) : t("none.what_here"));
  const name = make("input", { id: "new-name", value: "my-robot", spellcheck: false, maxLength: 64 });
  name.setAttribute("aria-label", t("none.name_aria"));
  const templates = config.templates || [];
  const starts = make("p", { className: "starts" }, name, ` ${t("none.from")} `, ...templates.map((template) => button(template,
    () => send({ op: "new", template, name: name.value.trim() }), { className: "primary" })));
  const commands = make("ul", { className: "commands" }, ...templates.map((template) =>
    make("li", {}, make("code", {}, `tablebot new my-robot --from ${template}`))));
  byId("grid").replaceChildren(make("div", { className: "no-table", role: "status" },
    make("h2", {}, t("none.title")), what, starts,
    make("p", {}, t("none.terminal")), commands,
    make("p", {}, t("none.then") + " ", make("code", {}, "tablebot studio my-robot"), " " + t("none.or_start"))));
  byId("save-state").textContent = t("none.state");
}

function showFile(store) {
  // nothing to save (no table, or no edit since it was read or saved): Save is off
  store.on(["dirty", "path"], ({ dirty, path }) => {
    if (path) byId("save-state").textContent = dirty ? t("file.unsaved") : t("file.saved");
    byId("save").classList.toggle("primary", Boolean(dirty));
    byId("save").disabled = !path || !dirty;
    byId("add-row").disabled = byId("del-row").disabled = byId("share").disabled = !path;
  });
  store.on(["path"], ({ path }) => {
    byId("table-pick").value = path;
    document.title = `${path} · tablebot studio`;
  });
  store.on(["files"], ({ files, path }) => {
    const tables = byId("table-pick"), traces = byId("trace-pick");
    tables.replaceChildren();
    traces.replaceChildren(make("option", { value: "" }, t("trace.choose")));
    files.tables.forEach((name) => addOption(tables, name));
    files.traces.forEach((name) => addOption(traces, name));
    if (path) tables.value = path;
  });
}

// Live robot or trace player: the controls, the timeline and what the arena shows.
function showMode(store, views, send) {
  store.on(["mode"], ({ mode }) => {
    byId("mode-live").classList.toggle("on", mode === "live");
    byId("mode-trace").classList.toggle("on", mode === "trace");
    byId("live-controls").hidden = mode !== "live";
    byId("trace-controls").hidden = mode !== "trace";
    byId("timeline").hidden = mode !== "trace";
    views.player.pause();
    if (mode === "live") arenaNote("");
    else send({ op: "sim", action: "pause" });
    views.arena.replayPath = null;
    views.arena.clearPath();
    views.arena.resize();
  });
}

// A robot of several tables: a tab for each (named as in the robot file's [tables]); a click shows that table,
// its edits kept by the server while another is shown. The arena runs all of them whichever is shown.
function showTableTabs(store, send) {
  store.on(["analysis", "path", "dirty"], ({ analysis, path, dirty }) => {
    const tabs = (analysis && analysis.tables) || [];
    const holder = byId("table-tabs");
    holder.hidden = tabs.length < 2;
    holder.replaceChildren(...tabs.map(({ name, file }) => {
      const on = file === path;
      const tab = button(name + (on && dirty ? " •" : ""), () => { if (!on) send({ op: "open", path: file }); },
        { className: on ? "on" : "", title: t("tabs.title", { name, file }) });
      tab.setAttribute("role", "tab");
      tab.setAttribute("aria-selected", String(on));
      tab.dataset.table = name;
      return tab;
    }));
  });
}

export function showPanels(store, views, send) {
  showTableTabs(store, send);
  showAnalysis(store, views);
  showFrames(store, views);
  showWhy(store, views);
  showInputs(store, send);
  showControls(store);
  showFile(store);
  showMode(store, views, send);
}

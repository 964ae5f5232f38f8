// The studio's views (grid, arena, diagram, timeline, trace player, checks), made once and wired to the
// store and the server: what the user does in a view becomes a message or a change of state.
import { stateColours } from "../lib/colours.js";
import { byId } from "../lib/dom.js";
import { t } from "../lib/words.js";
import { Arena } from "../views/arena.js";
import { Checks } from "../views/checks.js";
import { Diagram } from "../views/diagram.js";
import { Grid } from "../views/grid.js";
import { Player } from "../views/player.js";
import { Timeline } from "../views/timeline.js";

/** The column of the grid that holds the state (-1 while the table does not read). */
export function stateColumn(store) {
  const analysis = store.get().analysis;
  return analysis ? analysis.columns.findIndex((c) => c.kind === "state") : -1;
}

function makeGrid(store, send, edited) {
  const grid = new Grid(byId("grid"), {
    onEdit: (row, col, value) => {
      const seq = store.get().seq + 1;
      store.set({ seq, editSent: performance.now() });
      send({ op: "edit", row, col, value, seq });
      edited();
    },
  });
  byId("grid").addEventListener("focusin", (e) => {
    const td = e.target.closest("td[data-row]");
    if (td) store.set({ selectedRow: +td.dataset.row });
  });
  return grid;
}

// A click in the arena moves the start pose (a drag also aims it) or the lamp, and starts over.
function makeArena(store, send) {
  return new Arena(byId("arena"), stateColours(store), (x, y, heading) => {
    const { mode, clickMode, world } = store.get();
    if (mode !== "live") return;
    if (clickMode === "lamp") send({ op: "sim", action: "reset", lamp: [x, y] });
    else send({ op: "sim", action: "reset", start: [x, y, heading === null ? world.start[2] : heading] });
  });
}

function makeChecks(store, send, grid) {
  const els = { problems: byId("problems"), findings: byId("findings"), properties: byId("properties"),
    showInfo: byId("show-info"), verdicts: byId("verdicts") };
  return new Checks(els, {
    select: (rows, col) => {
      grid.select(rows);
      if (col !== undefined && col !== null) grid.focusCell(rows[0], col);
    },
    counterexample: (name, where) => {
      if (where === "table") store.set({ mode: "trace" });
      else {  // played in the arena at once; marked where it breaks (panels.js)
        const p = ((store.get().analysis || {}).properties || []).find((q) => q.name === name);
        store.set({ mode: "live", cex: p ? { ...p, shown: false } : null });
      }
      send({ op: "counterexample", name, where });
    },
  });
}

// An edit may give the states other colours (a state added that asks for a taken one): what a trace drew
// is drawn again; the live path keeps what it drew (the page keeps no copy of it). An empty timeline (no trace
// loaded) is left as it is: drawing it measures the page, which made the browser lay the whole page out at
// once, in the middle of each analysis (~45 ms of every table opened and every edit, headless).
function repaintStates({ arena, timeline }) {
  if (timeline.states.length) timeline.draw();
  if (arena.replayPath) { arena.clearPath(); arena.addPath(arena.replayPath); }
}

/** The views; `edited` is called after each edit in the grid. */
export function createViews(store, send, edited) {
  const grid = makeGrid(store, send, edited);
  const arena = makeArena(store, send);
  // enlarged over the table (and the checks beside the robot), never over the arena
  const diagram = new Diagram(byId("diagram"), { bigPlace: () => (document.body.dataset.layout === "stack"
    ? byId("grid") : document.querySelector("main .left")).getBoundingClientRect() });
  const views = { grid, arena, diagram };
  views.timeline = new Timeline(byId("timeline"), stateColours(store), (i) => views.player.seek(i));
  views.player = new Player({ arena, grid, diagram, timeline: views.timeline, status: byId("status"),
    slider: byId("scrub"), stateCol: () => stateColumn(store),
    onEnd: () => { byId("tplay").textContent = t("live.play"); }, onSeek: (tick) => store.set({ mask: tick.event }) });
  views.checks = makeChecks(store, send, grid);
  store.on(["machine"], ({ machine, mode }) => {
    // a trace playing when another tab is shown: that table speaks from the tick it is at (it kept the old one)
    if (mode === "trace") views.player.show(machine);
    repaintStates(views);
  });
  return views;
}

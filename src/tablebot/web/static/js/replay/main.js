// The stand-alone replay page: the data is in the page itself; the same views as the studio's trace player.
import { stateColours } from "../lib/colours.js";
import { byId, make } from "../lib/dom.js";
import { createStore } from "../lib/store.js";
import { Arena } from "../views/arena.js";
import { Diagram } from "../views/diagram.js";
import { Grid } from "../views/grid.js";
import { Player, wirePlayerControls, wireZoom } from "../views/player.js";
import { Timeline } from "../views/timeline.js";
import { chooseLanguage, setLanguage, t, translatePage, wireSwitch } from "../lib/words.js";

function showInputs(machine, mask) {
  byId("inputs").replaceChildren(...machine.inputs.map((name) => make("span", {
    className: "input" + (mask & machine.input_bits[name] ? " live" : ""), title: machine.labels[name] || name }, name)));
}

function replay(data) {
  document.title = data.title + " · tablebot replay";
  byId("title").textContent = data.title;
  const grid = new Grid(byId("grid"), { readOnly: true });
  grid.setColumns(data.table.columns, data.machine.tick_ms);
  grid.setTable(data.table.header, data.table.grid, data.table.lines);
  const colourOf = stateColours(createStore({ machine: data.machine }));
  const arena = new Arena(byId("arena"), colourOf, null);
  arena.setWorld(data.world);
  const diagram = new Diagram(byId("diagram"));
  diagram.setSvg(data.diagram);
  const stateCol = data.table.columns.findIndex((c) => c.kind === "state");
  const timeline = new Timeline(byId("timeline"), colourOf, (i) => player.seek(i));
  const player = new Player({ arena, grid, diagram, timeline, status: byId("status"), slider: byId("scrub"),
    stateCol: () => stateCol, onEnd: () => { byId("tplay").textContent = t("live.play"); },
    onSeek: (tick) => showInputs(data.machine, tick.event) });
  player.load(data.trace, data.machine, 0);
  wirePlayerControls(player);
  wireZoom(arena);
  arena.invalidate();  // drawn now, and again whenever it changes
}

const holder = byId("tb-data");
setLanguage(chooseLanguage(null));  // the reader's: the switch's choice, else the browser's
translatePage();
wireSwitch(byId("language"));
if (holder) replay(JSON.parse(holder.textContent));

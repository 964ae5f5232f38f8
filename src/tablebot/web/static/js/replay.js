// The stand-alone replay page: the data is in the page itself; the same views as the studio's trace player.
"use strict";

(function () {
  const holder = document.getElementById("tb-data");
  if (!holder) return;  // inlined into the studio by mistake: nothing to do
  const data = JSON.parse(holder.textContent);
  const $ = (id) => document.getElementById(id);
  document.title = data.title + " · tablebot replay";
  $("title").textContent = data.title;
  const grid = new TB.Grid($("grid"), { readOnly: true });
  grid.setColumns(data.table.columns, data.machine.tick_ms);
  grid.setTable(data.table.header, data.table.grid, data.table.lines);
  const arena = new TB.Arena($("arena"), null);
  arena.setWorld(data.world);
  const diagram = new TB.Diagram($("diagram"));
  diagram.setSvg(data.diagram);
  $("diagram").addEventListener("click", () => $("diagram").classList.toggle("big"));
  const stateCol = data.table.columns.findIndex(c => c.kind === "state");
  const machine = data.machine;
  function renderInputs(mask) {
    const box = $("inputs");
    box.textContent = "";
    for (const name of machine.inputs) {
      const b = document.createElement("span");
      b.className = "input" + (mask & machine.input_bits[name] ? " live" : "");
      b.textContent = name;
      b.title = machine.labels[name] || name;
      box.appendChild(b);
    }
  }
  const timeline = new TB.Timeline($("timeline"), (i) => player.seek(i));
  const player = new TB.Player({ arena, grid, diagram, timeline, status: $("status"), slider: $("scrub"),
    stateCol: () => stateCol, onEnd: () => { $("tplay").textContent = "▶ Play"; }, onSeek: (t) => renderInputs(t.event) });
  player.load(data.trace, machine, 0);
  TB.wirePlayerControls($, player);
  TB.wireZoom($, arena);
  (function paint() { arena.draw(); requestAnimationFrame(paint); })();
  TB.replay = player;
})();

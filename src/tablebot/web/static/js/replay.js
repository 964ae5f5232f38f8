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
  $("tplay").addEventListener("click", () => {
    if (player.playing) { player.pause(); $("tplay").textContent = "▶ Play"; } else { player.play(); $("tplay").textContent = "❚❚ Pause"; }
  });
  $("scrub").addEventListener("input", (e) => player.seek(+e.target.value));
  document.querySelectorAll("[data-tspeed]").forEach(b => b.addEventListener("click", () => {
    player.speed = +b.dataset.tspeed;
    if (player.playing) player.play(player.speed);
    document.querySelectorAll("[data-tspeed]").forEach(o => o.classList.toggle("on", o === b));
  }));
  let zoom = 1;
  const setZoom = (z) => { zoom = Math.max(0.8, Math.min(1.6, z)); document.documentElement.style.setProperty("--zoom", zoom); arena.resize(); };
  $("smaller").addEventListener("click", () => setZoom(zoom - 0.1));
  $("bigger").addEventListener("click", () => setZoom(zoom + 0.1));
  (function paint() { arena.draw(); requestAnimationFrame(paint); })();
  TB.replay = player;
})();

// The studio page: one WebSocket to the server; the grid, checks, arena, diagram and trace player wired to it.
"use strict";

(function () {
  const $ = (id) => document.getElementById(id);
  const state = { machine: null, analysis: null, seq: 0, mode: "live", frame: null, clickMode: "start",
    speed: "1", paused: true, world: null, tickMs: 10, dirty: false, selectedRow: null, held: {} };
  TB.stats = { frames: 0, ticks: 0, lastTick: -1, drawMs: 0, messages: 0, analysisMs: [] };
  let socket = null;
  const pending = [];

  function send(message) {
    if (socket && socket.readyState === WebSocket.OPEN) socket.send(JSON.stringify(message));
    else pending.push(message);
  }

  // --- the views ---------------------------------------------------------------------------------------
  const grid = new TB.Grid($("grid"), { onEdit: (row, col, value) => {
    state.seq += 1; state.editSent = performance.now();
    send({ op: "edit", row, col, value, seq: state.seq });
  } });
  $("grid").addEventListener("focusin", (e) => {
    const td = e.target.closest("td[data-row]");
    if (td) state.selectedRow = +td.dataset.row;
  });
  const arena = new TB.Arena($("arena"), (x, y, heading) => {
    if (state.mode !== "live") return;
    if (state.clickMode === "lamp") send({ op: "sim", action: "reset", lamp: [x, y] });
    else send({ op: "sim", action: "reset", start: [x, y, heading === null ? state.world.start[2] : heading] });
  });
  const diagram = new TB.Diagram($("diagram"));
  $("diagram").addEventListener("click", () => $("diagram").classList.toggle("big"));
  const timeline = new TB.Timeline($("timeline"), (i) => player.seek(i));
  const stateCol = () => (state.analysis ? state.analysis.columns.findIndex(c => c.kind === "state") : -1);
  const player = new TB.Player({ arena, grid, diagram, timeline, status: $("status"), slider: $("scrub"), stateCol,
    onEnd: () => { $("tplay").textContent = "▶ Play"; }, onSeek: (t) => renderInputs(t.event) });
  const checks = new TB.Checks({ problems: $("problems"), findings: $("findings"), properties: $("properties"),
    showInfo: $("show-info") }, {
    select: (rows, col) => {
      grid.select(rows);
      if (col !== undefined && col !== null) { const el = grid._td(rows[0], col); if (el) el.querySelector("input,button").focus(); }
    },
    counterexample: (name, where) => { if (where === "table") setMode("trace"); send({ op: "counterexample", name, where }); },
  });

  // --- messages from the server ------------------------------------------------------------------------
  const on = {
    table(m) {
      state.path = m.path;
      grid.setTable(m.header, m.grid, m.lines);
      $("table-pick").value = m.path;
      document.title = `${m.path} · tablebot studio`;
      setDirty(false);
    },
    grid(m) { grid.setTable(grid.header, m.grid, grid.lines); },
    analysis(m) {
      if (m.seq !== null && m.seq !== state.seq) return;  // an answer to an older edit
      state.analysis = m;
      if (m.machine) state.machine = m.machine;
      if (m.seq !== null && state.editSent) TB.stats.analysisMs.push(performance.now() - state.editSent);
      grid.lines = m.lines;
      grid.setColumns(m.columns, m.machine ? m.machine.tick_ms : state.tickMs);
      grid.setDiagnostics(m.diagnostics);
      grid.setFindings(m.findings || []);
      checks.render(m);
      if (m.seq !== null) setDirty(m.dirty);
      const c = m.counts || {};
      $("counts").textContent = m.ok
        ? `${m.machine.rows} rows · ${m.machine.states.length} states · ${c.error || 0} errors · ${c.warning || 0} warnings`
        : `${m.diagnostics.length} problem${m.diagnostics.length === 1 ? "" : "s"}: the table does not read`;
      $("counts").className = "counts " + (m.ok ? (c.error ? "bad" : c.warning ? "warn" : "good") : "bad");
      $("analysis-time").textContent = `checked in ${m.ms} ms`;
      renderInputs();
    },
    diagram(m) { diagram.setSvg(m.svg); if (state.frame) diagram.highlight(state.frame.state_id); },
    arena(m) {
      const note = $("arena-note");
      $("play").disabled = !m.ok;
      if (!m.ok) { note.textContent = m.problem; note.hidden = false; return; }
      note.hidden = true;
      state.world = m.world; state.tickMs = m.tick_ms;
      arena.replayPath = null;
      arena.setWorld(m.world);
      $("seed").value = m.settings.seed;
      $("battery").value = Math.round(100 * m.settings.charge);
      $("battery-text").textContent = Math.round(100 * m.settings.charge) + "%";
      state.frame = null;
      control(m);
    },
    control,
    frame(m) {
      TB.stats.frames += 1; TB.stats.ticks = m.tick; TB.stats.lastTick = m.tick;
      state.frame = m;
      control(m);
      if (state.mode !== "live") return;
      arena.addPath(m.path);
      arena.setRobot(m.pose, m.bumpers, m.light);
      grid.setLive(m.fired.length ? m.fired[m.fired.length - 1][1] : (m.paused ? m.row : grid.firedRow), m.state_id, stateCol());
      diagram.highlight(m.state_id);
      const outputs = {};
      (state.machine ? state.machine.outputs : []).forEach((name, i) => { outputs[name] = m.outputs[i]; });
      $("status").textContent = TB.describeTick(state.machine, { tick: m.tick, state: m.state_id, timer: m.timer,
        event: m.event, row: m.row, outputs });
      renderWhy(m.why || []);
      renderInputs(m.mask);
    },
    trace(m) {
      setMode("trace");
      addOption($("trace-pick"), m.name);
      $("trace-pick").value = m.name;
      if (!state.machine) { banner("open a table that reads before playing a trace", "bad"); return; }
      player.load(m.columns, state.machine, m.at_tick);
      renderWhy([]);
      const note = $("arena-note");
      note.hidden = "x" in m.columns;
      note.textContent = "this trace has no robot pose (a replay, a counterexample or a real robot): "
        + "the table, the diagram and the timeline follow it; the arena cannot";
    },
    files(m) { fillPicks(m); },
    saved(m) { setDirty(false); banner(`saved ${m.path} (the previous version is ${m.backup})`, "good"); },
    conflict(m) { banner(m.message + " — " + m.hint, "bad", [["Reload", () => send({ op: "open", path: state.path })],
      ["Save anyway", () => send({ op: "save", force: true })]]); },
    notice(m) { banner(m.message, "good"); },
    error(m) { banner(m.message, "bad"); },
  };

  function control(m) {
    state.paused = m.paused; state.speed = m.speed; state.held = m.held || {};
    $("play").textContent = m.paused ? "▶ Play" : "❚❚ Pause";
    document.querySelectorAll("[data-speed]").forEach(b => b.classList.toggle("on", b.dataset.speed === m.speed));
    $("step").disabled = !m.paused;
    if (m.error) banner("the live robot stopped: " + m.error, "bad");
  }

  // --- the machine panel: hand-held inputs and why rows fired -------------------------------------------
  function renderInputs(mask) {
    const box = $("inputs"), machine = state.machine;
    if (!machine) { box.textContent = ""; return; }
    box.textContent = "";
    for (const name of machine.inputs) {
      const b = document.createElement("button");
      b.type = "button"; b.dataset.input = name;
      const held = state.held[name];
      const live = mask !== undefined && (mask & machine.input_bits[name]);
      b.className = "input" + (live ? " live" : "") + (held === true ? " held-on" : held === false ? " held-off" : "");
      b.textContent = name + (held === true ? ": held on" : held === false ? ": held off" : "");
      b.disabled = state.mode !== "live";
      b.title = (machine.labels[name] || name) + ": click to hold it on, again to hold it off, again to let the sensor decide";
      b.addEventListener("click", () => {
        const next = held === undefined ? true : held === true ? false : null;
        send({ op: "sim", action: "hold", input: name, on: next });
      });
      box.appendChild(b);
    }
  }

  function renderWhy(items) {
    const list = $("why");
    list.textContent = "";
    for (const item of items) {
      const li = document.createElement("li");
      li.className = "why-" + item.status;
      li.textContent = item.why;
      if (item.row !== null) li.addEventListener("click", () => grid.select([item.row]));
      list.appendChild(li);
    }
  }

  // --- toolbar -------------------------------------------------------------------------------------------
  function setDirty(dirty) {
    state.dirty = dirty;
    $("save-state").textContent = dirty ? "unsaved edits" : "saved";
    $("save").classList.toggle("primary", dirty);
  }

  function banner(text, kind, buttons) {
    const b = $("banner");
    b.textContent = text; b.className = "banner " + (kind || ""); b.hidden = false;
    for (const [label, action] of buttons || []) {
      const btn = document.createElement("button"); btn.type = "button"; btn.textContent = label;
      btn.addEventListener("click", () => { b.hidden = true; action(); });
      b.appendChild(btn);
    }
    const close = document.createElement("button"); close.type = "button"; close.textContent = "×"; close.className = "close";
    close.addEventListener("click", () => { b.hidden = true; });
    b.appendChild(close);
    clearTimeout(state.bannerTimer);
    if (kind === "good") state.bannerTimer = setTimeout(() => { b.hidden = true; }, 6000);
  }

  function addOption(select, value) {
    if ([...select.options].some(o => o.value === value)) return;
    const o = document.createElement("option"); o.value = value; o.textContent = value; select.appendChild(o);
  }

  function fillPicks(m) {
    const tables = $("table-pick"), traces = $("trace-pick");
    tables.textContent = ""; traces.textContent = "";
    addOption(traces, "");
    traces.options[0].textContent = "choose a trace…";
    m.tables.forEach(t => addOption(tables, t));
    m.traces.forEach(t => addOption(traces, t));
    if (state.path) tables.value = state.path;
  }

  function setMode(mode) {
    state.mode = mode;
    $("mode-live").classList.toggle("on", mode === "live");
    $("mode-trace").classList.toggle("on", mode === "trace");
    $("live-controls").hidden = mode !== "live";
    $("trace-controls").hidden = mode !== "trace";
    $("timeline").hidden = mode !== "trace";
    player.pause();
    if (mode === "live") $("arena-note").hidden = true;
    arena.replayPath = null;
    arena.clearPath();
    if (mode === "live") { renderInputs(); } else { send({ op: "sim", action: "pause" }); }
    arena.resize();
  }

  $("save").addEventListener("click", () => send({ op: "save" }));
  $("table-pick").addEventListener("change", (e) => {
    if (state.dirty && !confirm("The table has unsaved edits. Open another and lose them?")) { e.target.value = state.path; return; }
    send({ op: "open", path: e.target.value });
  });
  $("mode-live").addEventListener("click", () => setMode("live"));
  $("mode-trace").addEventListener("click", () => setMode("trace"));
  $("play").addEventListener("click", () => send({ op: "sim", action: state.paused ? "play" : "pause" }));
  $("step").addEventListener("click", () => send({ op: "sim", action: "step" }));
  document.querySelectorAll("[data-speed]").forEach(b => b.addEventListener("click",
    () => send({ op: "sim", action: "speed", speed: b.dataset.speed })));
  document.querySelectorAll("[data-click]").forEach(b => b.addEventListener("click", () => {
    state.clickMode = b.dataset.click;
    document.querySelectorAll("[data-click]").forEach(o => o.classList.toggle("on", o === b));
  }));
  $("battery").addEventListener("input", () => { $("battery-text").textContent = $("battery").value + "%"; });
  $("battery").addEventListener("change", () => reset());
  $("reset").addEventListener("click", () => reset());
  function reset() {
    send({ op: "sim", action: "reset", seed: Math.max(0, parseInt($("seed").value, 10) || 0),
      charge: +$("battery").value / 100 });
  }
  $("add-row").addEventListener("click", () => send({ op: "insert_row", after: state.selectedRow === null ? grid.values.length - 1 : state.selectedRow }));
  $("del-row").addEventListener("click", () => { if (state.selectedRow !== null) send({ op: "delete_row", row: state.selectedRow }); });
  $("trace-pick").addEventListener("change", (e) => { if (e.target.value) send({ op: "trace", path: e.target.value }); });
  $("trace-file").addEventListener("change", async (e) => {
    const file = e.target.files[0];
    if (!file) return;
    const reply = await fetch("/api/trace?name=" + encodeURIComponent(file.name), { method: "POST", body: file });
    const m = (reply.headers.get("content-type") || "").startsWith("application/json")
      ? await reply.json() : { type: "error", message: await reply.text() };
    (on[m.type] || on.error)(m);
  });
  TB.wirePlayerControls($, player);
  TB.wireZoom($, arena);
  document.addEventListener("keydown", (e) => {
    if ((e.ctrlKey || e.metaKey) && e.key === "s") { e.preventDefault(); send({ op: "save" }); }
  });
  window.addEventListener("beforeunload", (e) => { if (state.dirty) { e.preventDefault(); e.returnValue = ""; } });

  // --- drawing and connecting ----------------------------------------------------------------------------
  function paint() {
    const t0 = performance.now();
    arena.draw();
    TB.stats.drawMs = performance.now() - t0;
    requestAnimationFrame(paint);
  }
  requestAnimationFrame(paint);

  async function start() {
    // the token came in the address (the server keeps it in an HttpOnly cookie): out of sight and history
    const params = new URLSearchParams(location.search);
    if (params.has("token")) {
      params.delete("token");
      history.replaceState(null, "", location.pathname + (params.toString() ? "?" + params : ""));
    }
    const reply = await fetch("/api/config");
    if (!reply.ok) { banner(await reply.text(), "bad"); return; }
    const config = await reply.json();
    fillPicks(config);
    const wanted = new URLSearchParams(location.search).get("table") || config.table || config.tables[0];
    socket = new WebSocket((location.protocol === "https:" ? "wss://" : "ws://") + location.host + "/ws");
    socket.addEventListener("open", () => {
      if (wanted) send({ op: "open", path: wanted });
      while (pending.length) socket.send(JSON.stringify(pending.shift()));
    });
    socket.addEventListener("message", (e) => {
      TB.stats.messages += 1;
      const m = JSON.parse(e.data);
      (on[m.type] || (() => {}))(m);
    });
    socket.addEventListener("close", () => banner("the studio server stopped: restart tablebot studio and reload", "bad"));
  }
  start();
})();

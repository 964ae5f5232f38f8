// The table as an editable grid: one input per cell, event and direction cells as toggles, the timer with
// its time beside it; errors on their cells, findings on their rows, the fired row and current state lit.
// User text only ever reaches the page through textContent and input values, never as HTML.
"use strict";
window.TB = window.TB || {};

TB.Grid = class {
  constructor(holder, options) {
    this.holder = holder;
    this.onEdit = options.onEdit || (() => {});
    this.readOnly = !!options.readOnly;
    this.note = document.createElement("div");
    this.note.className = "cell-note";
    this.note.hidden = true;
    this.columns = [];
    this.values = [];
    this.errors = new Map();  // "row:col" -> diagnostic (row -1: header)
    this.timers = new Map();
    this.tickMs = 10;
    this.focused = null;
    this.lastEdited = null;
  }

  setTable(header, rows, lines) {
    this.header = header;
    this.values = rows.map(r => r.slice());
    this.lines = lines || rows.map((_, i) => i + 2);
    this.render();
  }

  setColumns(columns, tickMs) {
    const changed = JSON.stringify(columns.map(c => c.kind)) !== JSON.stringify(this.columns.map(c => c.kind));
    this.columns = columns;
    if (tickMs) this.tickMs = tickMs;
    if (changed && this.header) this.render();
  }

  kind(col) { return (this.columns[col] || {}).kind || "unknown"; }

  render() {
    const table = document.createElement("table");
    table.className = "grid";
    const head = table.createTHead().insertRow();
    const corner = document.createElement("th");
    corner.textContent = "line"; corner.className = "num"; corner.title = "the line in the file";
    head.appendChild(corner);
    this.header.forEach((name, col) => {
      const th = document.createElement("th");
      th.dataset.col = col;
      th.className = "k-" + this.kind(col);
      const label = (this.columns[col] || {}).label || "";
      name.split("_").forEach((part, i) => {  // M1_speed may break after the underscore: narrow columns
        if (i) th.append("_", document.createElement("wbr"));
        th.append(part);
      });
      if (label) {
        const small = document.createElement("small");
        small.textContent = label;
        th.appendChild(small);
        th.title = name + ": " + label;
      }
      head.appendChild(th);
    });
    const body = table.createTBody();
    this.values.forEach((row, r) => body.appendChild(this._row(row, r)));
    this.holder.textContent = "";
    this.holder.appendChild(table);
    this.holder.appendChild(this.note);
    this.table = table;
    this._paintErrors();
  }

  _row(values, r) {
    const tr = document.createElement("tr");
    tr.dataset.row = r;
    const num = document.createElement("td");
    num.className = "num";
    num.textContent = this.lines[r];
    num.title = "row " + (r + 1) + ", line " + this.lines[r] + " of the file";
    tr.appendChild(num);
    values.forEach((value, c) => tr.appendChild(this._cell(value, r, c)));
    return tr;
  }

  _cell(value, r, c) {
    const td = document.createElement("td");
    td.dataset.row = r; td.dataset.col = c;
    const kind = this.kind(c);
    td.className = "k-" + kind;
    if (kind === "event" || kind === "dir") {
      const b = document.createElement("button");
      b.type = "button"; b.className = "flag";
      this._flag(b, value, kind);
      b.disabled = this.readOnly;
      b.addEventListener("click", () => this._toggle(r, c, b));
      b.addEventListener("focus", () => this._focus(r, c));
      td.appendChild(b);
      return td;
    }
    const input = document.createElement("input");
    input.value = value;
    input.spellcheck = false;
    input.readOnly = this.readOnly;
    input.setAttribute("aria-label", (this.header[c] || "") + " of row " + (r + 1));
    if (kind !== "description" && kind !== "unknown") input.inputMode = kind === "state" || kind === "next" ? "text" : "numeric";
    input.addEventListener("input", () => this._typed(r, c, input.value));
    input.addEventListener("focus", () => this._focus(r, c));
    input.addEventListener("keydown", (e) => this._keys(e, r, c));
    td.appendChild(input);
    if (kind === "timer") {
      const ms = document.createElement("span");
      ms.className = "ms";
      td.appendChild(ms);
      this._ms(ms, value);
    }
    return td;
  }

  _flag(button, value, kind) {
    const on = value.trim() === "1";
    button.setAttribute("aria-pressed", on ? "true" : "false");
    button.textContent = kind === "dir" ? (on ? "back" : "") : (on ? "1" : "");
    if (kind === "dir") button.title = on ? "1 = backward" : "blank = forward";
    if (kind === "event" && value.trim() && !on && value.trim() !== "0") button.textContent = value.trim();
  }

  _ms(span, value) {
    const v = value.trim();
    if (/^\d+$/.test(v) && +v > 0) {
      const ms = +v * this.tickMs;
      span.textContent = ms >= 1000 ? (ms / 1000).toFixed(ms % 1000 ? 2 : 0).replace(/\.?0+$/, "") + " s" : ms + " ms";
    } else span.textContent = "";
  }

  _toggle(r, c, button) {
    const on = this.values[r][c].trim() === "1";
    // off is written as the column writes it elsewhere: "0" if the file uses 0s, else a blank cell
    const zero = this.values.some(row => row[c].trim() === "0") ? "0" : "";
    const value = on ? zero : "1";
    this.values[r][c] = value;
    this._flag(button, value, this.kind(c));
    this.lastEdited = [r, c];
    this.onEdit(r, c, value);
  }

  _typed(r, c, value) {
    this.values[r][c] = value;
    this.lastEdited = [r, c];
    if (this.kind(c) === "timer") this._ms(this._td(r, c).querySelector(".ms"), value);
    clearTimeout(this.timers.get(r + ":" + c));
    this.timers.set(r + ":" + c, setTimeout(() => this.onEdit(r, c, value), 120));
  }

  _keys(e, r, c) {
    const move = { ArrowUp: -1, ArrowDown: 1, Enter: 1 }[e.key];
    if (move === undefined) return;
    const target = this._td(r + move, c);
    if (target) { e.preventDefault(); const el = target.querySelector("input,button"); if (el) el.focus(); }
  }

  _focus(r, c) { this.focused = [r, c]; this._showNote(); }

  _td(r, c) { return this.table && this.table.querySelector(`td[data-row="${r}"][data-col="${c}"]`); }

  _tr(r) { return this.table && this.table.querySelector(`tr[data-row="${r}"]`); }

  // --- what the checks say -------------------------------------------------------------------------------

  setDiagnostics(diagnostics) {
    this.errors.clear();
    for (const d of diagnostics) {
      if (d.row === null || d.row === undefined) continue;
      const key = d.row + ":" + (d.col === null || d.col === undefined ? "row" : d.col);
      if (!this.errors.has(key)) this.errors.set(key, d);
    }
    this._paintErrors();
  }

  _paintErrors() {
    if (!this.table) return;
    for (const el of this.table.querySelectorAll(".err")) { el.classList.remove("err"); el.removeAttribute("data-error"); }
    for (const [key, d] of this.errors) {
      const [r, c] = key.split(":");
      let el;
      if (r === "-1") el = this.table.querySelector(`th[data-col="${c}"]`) || this.table.tHead.rows[0].cells[0];
      else el = c === "row" ? (this._tr(r) || {}).firstChild : this._td(r, c);
      if (!el) continue;
      el.classList.add("err");
      el.dataset.error = d.message + (d.hint ? "\nhint: " + d.hint : "");
      el.title = d.text;
    }
    this._showNote();
  }

  // The located error of the focused cell (else of the cell last edited) in a note under it.
  _showNote() {
    const pick = [this.focused, this.lastEdited].find(p => p && (this.errors.has(p[0] + ":" + p[1]) || this.errors.has(p[0] + ":row")));
    if (!pick || !this.table) { this.note.hidden = true; return; }
    const d = this.errors.get(pick[0] + ":" + pick[1]) || this.errors.get(pick[0] + ":row");
    const td = this._td(pick[0], pick[1]);
    if (!td) { this.note.hidden = true; return; }
    this.note.textContent = "";
    const where = document.createElement("b");
    where.textContent = `line ${d.line}${d.column ? ", column " + d.column : ""}: `;
    this.note.append(where, d.message);
    if (d.hint) { const h = document.createElement("div"); h.className = "hint"; h.textContent = "hint: " + d.hint; this.note.appendChild(h); }
    this.note.hidden = false;
    this.note.style.left = Math.max(0, td.offsetLeft - 4) + "px";
    this.note.style.top = (td.offsetTop + td.offsetHeight + 2) + "px";
  }

  setFindings(findings) {
    if (!this.table) return;
    const rank = { error: 3, warning: 2, info: 1 };
    const worst = new Map();
    for (const f of findings) for (const r of f.rows) {
      const prev = worst.get(r);
      if (!prev || rank[f.severity] > rank[prev.severity]) worst.set(r, f);
    }
    this.table.querySelectorAll("tbody tr").forEach((tr) => {
      const f = worst.get(+tr.dataset.row);
      tr.firstChild.dataset.finding = f ? f.severity : "";
    });
  }

  select(rows) {
    if (!this.table) return;
    this.table.querySelectorAll("tr.selected").forEach(tr => tr.classList.remove("selected"));
    rows.forEach((r, i) => {
      const tr = this._tr(r);
      if (!tr) return;
      tr.classList.add("selected");
      if (i === 0) tr.scrollIntoView({ block: "nearest" });
    });
  }

  // The row that fired this tick (-1: none) and the state the machine is in (its id as text).
  setLive(row, stateId, stateCol) {
    if (!this.table) return;
    if (this.firedRow !== row) {
      const old = this._tr(this.firedRow);
      if (old) old.classList.remove("fired");
      const tr = this._tr(row);
      if (tr) { tr.classList.add("fired"); tr.scrollIntoView({ block: "nearest" }); }
      this.firedRow = row;
    }
    if (this.liveState !== stateId) {
      this.liveState = stateId;
      this.table.querySelectorAll("tbody tr").forEach((tr) => {
        const v = stateCol >= 0 ? (this.values[+tr.dataset.row] || [])[stateCol] : null;
        tr.classList.toggle("in-state", v !== null && v !== undefined && v.trim() === stateId);
      });
    }
  }
};

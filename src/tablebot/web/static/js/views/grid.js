// The table as an editable grid: one input per cell, event and direction cells as toggles, the timer with
// its time beside it; errors on their cells, findings on their rows, the fired row and current state lit.
// User text only ever reaches the page through textContent and input values, never as HTML.
import { make } from "../lib/dom.js";
import { number, t } from "../lib/words.js";

const RANK = { error: 3, warning: 2, info: 1 };
const TOGGLES = ["event", "dir"];
const MOVES = { ArrowUp: -1, ArrowDown: 1, Enter: 1 };

/** A timer's ticks as time in the page's language ("8,95 s" in German, "500 ms"); "" for anything else. The
 * cell itself keeps the ticks as typed: this is only the time shown beside them. */
function timeText(value, tickMs) {
  const v = value.trim();
  if (!/^\d+$/.test(v) || +v <= 0) return "";
  const ms = +v * tickMs;
  return ms >= 1000 ? number(ms / 1000) + " s" : number(ms) + " ms";
}

export class Grid {
  constructor(holder, { onEdit = () => {}, readOnly = false } = {}) {
    this.holder = holder;
    this.onEdit = onEdit;
    this.readOnly = readOnly;
    this.note = make("div", { className: "cell-note", hidden: true });
    this.columns = [];
    this.values = [];
    this.errors = new Map();  // "row:col" -> diagnostic (row -1: the header)
    this.timers = new Map();
    this.tickMs = 10;
    this.focused = null;
    this.lastEdited = null;
    this.firedRow = undefined;
    holder.addEventListener("scroll", () => { if (!this.note.hidden) this._showNote(); });
    this.rowLines = null;  // the machine's rows as file lines (row i of a trace fired line rowLines[i])
  }

  // columns and tickMs, when the table comes with them: its grid is drawn once, not again when its analysis comes
  setTable(header, rows, lines, columns, tickMs) {
    this.header = header;
    this.values = rows.map((r) => r.slice());
    this.lines = lines || rows.map((_, i) => i + 2);
    if (columns && columns.length) this.columns = columns;
    if (tickMs) this.tickMs = tickMs;
    this.render();
  }

  setColumns(columns, tickMs) {
    const changed = JSON.stringify(columns.map((c) => c.kind)) !== JSON.stringify(this.columns.map((c) => c.kind))
      || Boolean(tickMs && tickMs !== this.tickMs);  // the timers' times beside their cells
    this.columns = columns;
    if (tickMs) this.tickMs = tickMs;
    if (changed && this.header) this.render();
  }

  kind(col) { return (this.columns[col] || {}).kind || "unknown"; }

  render() {
    const table = make("table", { className: "grid" });
    const head = table.createTHead().insertRow();
    head.append(make("th", { className: "num", title: t("grid.line_title") }, t("grid.line")));
    this.header.forEach((name, col) => head.append(this._headCell(name, col)));
    const body = table.createTBody();
    this.values.forEach((row, r) => body.append(this._row(row, r)));
    this.holder.replaceChildren(table, this.note);
    this.table = table;
    this.firedRow = undefined;
    this.liveState = undefined;
    this._paintErrors();
  }

  _headCell(name, col) {
    const th = make("th", { className: "k-" + this.kind(col) });
    th.dataset.col = col;
    name.split("_").forEach((part, i) => {  // M1_speed on two lines, after its underscore: narrow columns
      if (i) th.append("_", make("br"));
      th.append(part);
    });
    const label = (this.columns[col] || {}).label || "";
    if (label) {
      th.append(make("small", {}, label));
      th.title = name + ": " + label;
    }
    return th;
  }

  _row(values, r) {
    const tr = make("tr");
    tr.dataset.row = r;
    tr.append(make("td", { className: "num", title: t("grid.line_of_file", { line: this.lines[r] }) }, String(this.lines[r])));
    values.forEach((value, c) => tr.append(this._cell(value, r, c)));
    return tr;
  }

  _cell(value, r, c) {
    const kind = this.kind(c);
    const td = make("td", { className: "k-" + kind });
    td.dataset.row = r; td.dataset.col = c;
    td.append(TOGGLES.includes(kind) ? this._toggleButton(value, r, c, kind) : this._fitted(this._input(value, r, c, kind)));
    if (kind === "timer") td.append(make("span", { className: "ms" }, timeText(value, this.tickMs)));
    return td;
  }

  _toggleButton(value, r, c, kind) {
    const b = make("button", { type: "button", className: "flag", disabled: this.readOnly });
    this._flag(b, value, kind);
    b.addEventListener("click", () => this._toggle(r, c, b));
    b.addEventListener("focus", () => this._focus(r, c));
    return b;
  }

  // A cell's text is never cut: the input sits in a box that a hidden copy of its text sizes (a description
  // wraps onto more lines instead, in a textarea as tall as its text).
  _fitted(input) {
    const box = make("span", { className: input.tagName === "TEXTAREA" ? "fit wrap" : "fit" });
    box.dataset.value = input.value;
    box.append(input);
    return box;
  }

  _input(value, r, c, kind) {
    const wraps = kind === "description";
    const input = make(wraps ? "textarea" : "input", { value, spellcheck: false, readOnly: this.readOnly });
    if (wraps) input.rows = 1;  // (and the smallest box of its own: the hidden copy beside it sizes it)
    if (wraps) input.cols = 1; else input.size = 1;
    input.setAttribute("aria-label", t("grid.cell", { column: this.header[c] || "", line: this.lines[r] }));
    if (kind !== "description" && kind !== "unknown") input.inputMode = kind === "state" || kind === "next" ? "text" : "numeric";
    input.addEventListener("input", () => this._typed(r, c, input.value));
    input.addEventListener("focus", () => this._focus(r, c));
    input.addEventListener("keydown", (e) => this._keys(e, r, c));
    return input;
  }

  _flag(button, value, kind) {
    const v = value.trim(), on = v === "1";
    button.setAttribute("aria-pressed", on ? "true" : "false");
    button.textContent = kind === "dir" ? (on ? t("grid.back") : "") : (on ? "1" : "");
    if (kind === "dir") button.title = on ? t("grid.backward") : t("grid.forward");
    if (kind === "event" && v && !on && v !== "0") button.textContent = v;
  }

  _toggle(r, c, button) {
    const on = this.values[r][c].trim() === "1";
    // off is written as the column writes it elsewhere: "0" if the file uses 0s, else a blank cell
    const zero = this.values.some((row) => row[c].trim() === "0") ? "0" : "";
    const value = on ? zero : "1";
    this.values[r][c] = value;
    this._flag(button, value, this.kind(c));
    this.lastEdited = [r, c];
    this.onEdit(r, c, value);
  }

  _typed(r, c, value) {
    this.values[r][c] = value;
    this.td(r, c).querySelector(".fit").dataset.value = value;
    this.lastEdited = [r, c];
    if (this.kind(c) === "timer") this.td(r, c).querySelector(".ms").textContent = timeText(value, this.tickMs);
    clearTimeout(this.timers.get(r + ":" + c));
    this.timers.set(r + ":" + c, setTimeout(() => this.onEdit(r, c, value), 120));
  }

  _keys(e, r, c) {
    const move = MOVES[e.key];
    if (move === undefined) return;
    if (e.key === "Enter") e.preventDefault();  // a cell holds one line, even a description's textarea
    if (!this.td(r + move, c)) return;
    e.preventDefault();
    this.focusCell(r + move, c);
  }

  _focus(r, c) { this.focused = [r, c]; this._showNote(); }

  td(r, c) { return this.table && this.table.querySelector(`td[data-row="${r}"][data-col="${c}"]`); }

  _tr(r) { return this.table && this.table.querySelector(`tr[data-row="${r}"]`); }

  /** Put the cursor into a cell (its input or toggle). */
  focusCell(r, c) {
    const control = this.td(r, c) && this.td(r, c).querySelector("input,button");
    if (control) control.focus();
  }

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

  _errorPlace(key) {
    const [r, c] = key.split(":");
    if (r === "-1") return this.table.querySelector(`th[data-col="${c}"]`) || this.table.tHead.rows[0].cells[0];
    return c === "row" ? (this._tr(r) || {}).firstChild : this.td(r, c);
  }

  _paintErrors() {
    if (!this.table) return;
    for (const el of this.table.querySelectorAll(".err")) { el.classList.remove("err"); el.removeAttribute("data-error"); }
    for (const [key, d] of this.errors) {
      const el = this._errorPlace(key);
      if (!el) continue;
      el.classList.add("err");
      el.dataset.error = d.message + (d.hint ? "\nhint: " + d.hint : "");
      el.title = d.text;
    }
    this._showNote();
  }

  _errorAt(place) {
    return place && (this.errors.get(place[0] + ":" + place[1]) || this.errors.get(place[0] + ":row"));
  }

  // The located error of the focused cell (else of the cell last edited) in a note under it.
  _showNote() {
    const pick = [this.focused, this.lastEdited].find((p) => this._errorAt(p));
    const td = pick && this.table && this.td(pick[0], pick[1]);
    if (!td) { this.note.hidden = true; return; }
    const d = this._errorAt(pick);
    this.note.replaceChildren(make("b", {}, d.column ? t("grid.where_column", { line: d.line, column: d.column }) : t("grid.where", { line: d.line })), d.message);
    if (d.hint) this.note.append(make("div", { className: "hint" }, t("checks.hint", { hint: d.hint })));
    this.note.hidden = false;
    this._placeNote(td);
  }

  // Under its cell (above it near the window's bottom), kept inside the window: the note is fixed to the
  // window, so the grid's edge never cuts it, however far right the column is.
  _placeNote(td) {
    const cell = td.getBoundingClientRect(), note = this.note.getBoundingClientRect();
    const left = Math.max(8, Math.min(cell.left - 4, window.innerWidth - note.width - 8));
    const below = cell.bottom + 2 + note.height <= window.innerHeight - 8;
    this.note.style.left = left + "px";
    this.note.style.top = Math.max(8, below ? cell.bottom + 2 : cell.top - 2 - note.height) + "px";
  }

  setFindings(findings) {
    if (!this.table) return;
    const worst = new Map();
    for (const f of findings) {
      for (const r of f.rows) {
        const prev = worst.get(r);
        if (!prev || RANK[f.severity] > RANK[prev.severity]) worst.set(r, f);
      }
    }
    this.table.querySelectorAll("tbody tr").forEach((tr) => {
      const f = worst.get(+tr.dataset.row);
      tr.firstChild.dataset.finding = f ? f.severity : "";
    });
  }

  select(rows) {
    if (!this.table) return;
    this.table.querySelectorAll("tr.selected").forEach((tr) => tr.classList.remove("selected"));
    rows.forEach((r, i) => {
      const tr = this._tr(r);
      if (!tr) return;
      tr.classList.add("selected");
      if (i === 0) tr.scrollIntoView({ block: "nearest" });
    });
  }

  /** The grid row showing the machine's row ``row`` (an index into the table's rows, as a trace's ``row``):
   * the one on the same line of the file (a row blanked in the grid is no row of the machine). */
  gridRow(row) {
    if (row === null || row === undefined || row < 0) return -1;
    return this.rowLines ? this.lines.indexOf(this.rowLines[row]) : row;
  }

  // The machine's row that fired this tick (-1: none) and the state the machine is in (its id as text).
  setLive(machineRow, stateId, stateCol) {
    if (!this.table) return;
    const row = this.gridRow(machineRow);
    this.liveRow = machineRow;
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
}

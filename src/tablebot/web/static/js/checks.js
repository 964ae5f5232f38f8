// The checks panel: the parser's errors, check's findings and the property results, each clickable to
// select its rows; a broken property's counterexample can be played on the table or in the arena.
"use strict";
window.TB = window.TB || {};

TB.Checks = class {
  constructor(els, actions) {
    this.els = els;          // {problems, findings, properties, showInfo}
    this.actions = actions;  // {select(rows, cell), counterexample(name, where)}
    this.data = null;
    els.showInfo.addEventListener("change", () => this.render(this.data));
  }

  _item(list, severity, text, hint, onClick) {
    const li = document.createElement("li");
    li.className = "sev-" + severity;
    const tag = document.createElement("span");
    tag.className = "tag"; tag.textContent = severity;
    li.append(tag, " ", text);
    if (hint) { const h = document.createElement("div"); h.className = "hint"; h.textContent = "hint: " + hint; li.appendChild(h); }
    if (onClick) { li.tabIndex = 0; li.addEventListener("click", onClick); li.addEventListener("keydown", e => { if (e.key === "Enter") onClick(); }); }
    list.appendChild(li);
    return li;
  }

  render(data) {
    this.data = data;
    const { problems, findings, properties, showInfo } = this.els;
    for (const list of [problems, findings, properties]) list.textContent = "";
    if (!data) return;
    for (const d of data.diagnostics || []) {
      const where = d.line ? `${d.file}:${d.line}${d.column ? ":" + d.column : ""}: ` : `${d.file}: `;
      this._item(problems, d.severity, where + d.message, d.hint,
        d.row !== null && d.row !== undefined ? () => this.actions.select([d.row], d.col) : null);
    }
    const shown = (data.findings || []).filter(f => showInfo.checked || f.severity !== "info");
    for (const f of shown) {
      const where = f.lines.length ? `line ${f.lines.join(", ")}: ` : "";
      this._item(findings, f.severity, where + f.message, f.hint, f.rows.length ? () => this.actions.select(f.rows) : null);
    }
    const hidden = (data.findings || []).length - shown.length;
    if (hidden) {
      const li = document.createElement("li");
      li.className = "muted"; li.textContent = `${hidden} notes (overlaps, ignored inputs) hidden`;
      findings.appendChild(li);
    }
    for (const p of data.properties || []) this._property(properties, p);
    if (data.ok && !(data.findings || []).some(f => f.severity !== "info") && !(data.properties || []).some(p => p.severity)) {
      const li = document.createElement("li"); li.className = "sev-ok"; li.textContent = "no errors, no warnings";
      findings.prepend(li);
    }
  }

  _property(list, p) {
    const severity = p.status === "holds" ? "holds" : p.severity || "info";
    const word = p.status === "holds" ? "holds" : p.status === "violated" ? "VIOLATED" : "unknown";
    const li = this._item(list, severity, `${p.status === "holds" ? "" : word + ": "}${p.name}: ${p.text}`, p.status === "holds" ? "" : p.note, null);
    li.title = p.claim;
    if (p.detail) { const d = document.createElement("div"); d.className = "hint"; d.textContent = p.detail; li.appendChild(d); }
    if (p.ticks) {
      const bar = document.createElement("div");
      bar.className = "cex";
      bar.append(`${p.example ? "example" : "counterexample"}: ${p.ticks} ticks `);
      for (const [where, label] of [["table", "▶ on the table"], ["arena", "▶ in the arena"]]) {
        const b = document.createElement("button");
        b.type = "button"; b.textContent = label; b.dataset.where = where;
        b.addEventListener("click", (e) => { e.stopPropagation(); this.actions.counterexample(p.name, where); });
        bar.appendChild(b);
      }
      li.appendChild(bar);
    }
  }
};

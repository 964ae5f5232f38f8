// The checks panel: the parser's errors, check's findings and the property results, each clickable to
// select its rows; a broken property's counterexample can be played on the table or in the arena.
import { button, make } from "../lib/dom.js";
import { t } from "../lib/words.js";

const hasRow = (d) => d.row !== null && d.row !== undefined;

export class Checks {
  constructor(els, actions) {
    this.els = els;          // {problems, findings, properties, showInfo, verdicts}
    this.actions = actions;  // {select(rows, col), counterexample(name, where)}
    this.data = null;
    els.showInfo.addEventListener("change", () => this.render(this.data));
  }

  _item(list, severity, text, hint, onClick) {
    const li = make("li", { className: "sev-" + severity }, make("span", { className: "tag" }, t("severity." + severity)), " ", text);
    if (hint) li.append(make("div", { className: "hint" }, t("checks.hint", { hint })));
    if (onClick) {
      li.tabIndex = 0;
      li.addEventListener("click", onClick);
      li.addEventListener("keydown", (e) => { if (e.key === "Enter") onClick(); });
    }
    list.append(li);
    return li;
  }

  render(data) {
    this.data = data;
    const { problems, findings, properties } = this.els;
    for (const list of [problems, findings, properties, this.els.verdicts]) list.textContent = "";
    if (!data) return;
    this._problems(data.diagnostics || []);
    this._findings(data.findings || []);
    // the broken ones first; every verdict also in the strip at the top, which never scrolls away
    const props = [...(data.properties || [])].sort((a, b) => (a.status === "holds") - (b.status === "holds"));
    for (const p of props) this._verdict(this._property(properties, p), p);
    const quiet = !(data.findings || []).some((f) => f.severity !== "info") && !(data.properties || []).some((p) => p.severity);
    if (data.ok && quiet) findings.prepend(make("li", { className: "sev-ok" }, t("checks.clean")));
  }

  _problems(diagnostics) {
    for (const d of diagnostics) {
      const where = d.line ? `${d.file}:${d.line}${d.column ? ":" + d.column : ""}: ` : `${d.file}: `;
      this._item(this.els.problems, d.severity, where + d.message, d.hint,
        hasRow(d) ? () => this.actions.select([d.row], d.col) : null);
    }
  }

  _findings(all) {
    const shown = all.filter((f) => this.els.showInfo.checked || f.severity !== "info");
    for (const f of shown) {
      const where = f.lines.length ? t("checks.line", { lines: f.lines.join(", ") }) : "";
      this._item(this.els.findings, f.severity, where + f.message, f.hint,
        f.rows.length ? () => this.actions.select(f.rows) : null);
    }
    const hidden = all.length - shown.length;
    if (hidden) this.els.findings.append(make("li", { className: "muted" }, t("checks.hidden", { n: hidden })));
  }

  _property(list, p) {
    const holds = p.status === "holds";
    const word = p.status === "violated" ? t("checks.violated") : t("checks.unknown");
    const li = this._item(list, holds ? "holds" : p.severity || "info", `${holds ? "" : word + ": "}${p.name}: ${p.text}`,
      holds ? "" : p.note, null);
    li.title = p.claim;
    if (p.detail) li.append(make("div", { className: "hint" }, p.detail));
    if (p.ticks) li.append(this._replayBar(p));
    return li;
  }

  _verdict(li, p) {
    const mark = { holds: "✔", violated: "✘" }[p.status] || "?";
    const chip = button(`${mark} ${p.name}`, () => { li.scrollIntoView({ block: "nearest" }); li.focus(); },
      { className: "verdict v-" + p.status, title: `${p.name} ${t("status." + p.status)}: ${p.text}` });
    chip.dataset.property = p.name;
    li.tabIndex = -1;
    this.els.verdicts.append(make("li", {}, chip));
  }

  _replayBar(p) {
    const bar = make("div", { className: "cex" }, t(p.example ? "cex.example" : "cex.counterexample", { n: p.ticks }) + " ");
    for (const [where, label] of [["table", t("cex.on_table")], ["arena", t("cex.in_arena")]]) {
      const b = button(label, (e) => { e.stopPropagation(); this.actions.counterexample(p.name, where); });
      b.dataset.where = where;
      bar.append(b);
    }
    return bar;
  }
}

// The Share button's answer: the link that carries the table as edited (to paste into a chat, or to open with
// `tablebot studio --open LINK`) and its QR code, in the page's dialog.
import { byId, button, make } from "../lib/dom.js";

export function showShared(m) {
  const box = byId("ask");
  if (box.open) box.close();
  const text = make("textarea", { className: "share-link", readOnly: true, rows: 4, value: m.link, spellcheck: false });
  text.setAttribute("aria-label", "the link");
  const copy = button("Copy the link", async () => {
    text.select();
    try { await navigator.clipboard.writeText(m.link); copy.textContent = "copied"; } catch { copy.textContent = "selected: Ctrl+C copies it"; }
  }, { className: "primary" });
  const qr = m.qr ? make("img", { className: "share-qr", alt: "the link as a QR code", src: m.qr })
    : make("p", { className: "muted" }, "The link is too long for a QR code: share it as text.");
  box.replaceChildren(make("h2", {}, "Share this table"),
    make("p", {}, `The link (${m.link.length} characters) carries the table as it is on the page, its robot file `
      + "and its world: no server ever sees them. Whoever opens it in the studio (tablebot studio --open LINK) "
      + "gets this table, cell for cell, in a folder of their own."),
    text, qr, make("div", { className: "answers" }, copy, button("Close", () => box.close())));
  box.oncancel = null;
  box.showModal();
  text.select();
}

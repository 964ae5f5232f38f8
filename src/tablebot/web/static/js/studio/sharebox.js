// Links that carry a table: the Share button's answer (the link of the table as edited, to paste into a chat or
// open with `tablebot studio --open LINK`, and its QR code), and opening a link pasted in (the "Open a link"
// box, or the page's own address with #share=...), in the page's dialog.
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

/** The "Open a link" box: a link pasted in opens its table (written into a new folder of the served one). */
export function askForLink(send) {
  const box = byId("ask");
  if (box.open) box.close();
  const text = make("textarea", { className: "share-link", rows: 4, spellcheck: false,
    placeholder: "the link: …/#share=1.…" });
  text.setAttribute("aria-label", "the link to open");
  const open = button("Open", () => { box.close(); if (text.value.trim()) send({ op: "open_link", link: text.value.trim() }); },
    { className: "primary" });
  box.replaceChildren(make("h2", {}, "Open a shared table"),
    make("p", {}, "Paste a link that tablebot share or a Share button made: its table, robot file and world go into "
      + "a new folder here (nothing is written over), and the table opens, exactly as it was shared."),
    text, make("div", { className: "answers" }, open, button("Cancel", () => box.close())));
  box.oncancel = null;
  box.showModal();
  text.focus();
}

/** A link in the page's own address (#share=...: pasted into the browser's address bar): opened, then the
 * address is put back without it. */
export function openLinkInAddress(send) {
  if (!location.hash.includes("share=")) return;
  send({ op: "open_link", link: location.hash });
  history.replaceState(null, "", location.pathname + location.search);
}

// Links that carry a table: the Share button's answer (the link of the table as edited, to paste into a chat or
// open with `tablebot studio --open LINK`, and its QR code), and opening a link pasted in (the "Open a link"
// box, or the page's own address with #share=...), in the page's dialog.
import { byId, button, make } from "../lib/dom.js";
import { t } from "../lib/words.js";

export function showShared(m) {
  const box = byId("ask");
  if (box.open) box.close();
  const text = make("textarea", { className: "share-link", readOnly: true, rows: 4, value: m.link, spellcheck: false });
  text.setAttribute("aria-label", t("share.link"));
  const copy = button(t("share.copy"), async () => {
    text.select();
    try { await navigator.clipboard.writeText(m.link); copy.textContent = t("share.copied"); } catch { copy.textContent = t("share.selected"); }
  }, { className: "primary" });
  const qr = m.qr ? make("img", { className: "share-qr", alt: t("share.qr"), src: m.qr })
    : make("p", { className: "muted" }, t("share.no_qr"));
  box.replaceChildren(make("h2", {}, t("share.title")), make("p", {}, t("share.what", { n: m.link.length })),
    text, qr, make("div", { className: "answers" }, copy, button(t("share.close"), () => box.close())));
  box.oncancel = null;
  box.showModal();
  text.select();
}

/** The "Open a link" box: a link pasted in opens its table (written into a new folder of the served one). */
export function askForLink(send) {
  const box = byId("ask");
  if (box.open) box.close();
  const text = make("textarea", { className: "share-link", rows: 4, spellcheck: false,
    placeholder: t("openlink.placeholder") });
  text.setAttribute("aria-label", t("openlink.aria"));
  const open = button(t("openlink.open"), () => { box.close(); if (text.value.trim()) send({ op: "open_link", link: text.value.trim() }); },
    { className: "primary" });
  box.replaceChildren(make("h2", {}, t("openlink.title")), make("p", {}, t("openlink.what")),
    text, make("div", { className: "answers" }, open, button(t("openlink.cancel"), () => box.close())));
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

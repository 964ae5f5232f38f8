// A question the user answers before going on (a modal dialog): a title, a few lines, a button per answer.
import { byId, button, make } from "../lib/dom.js";

/** Ask; `answers` are [label, action, className]. Escape runs `onEscape`, or (none given) is not an answer. */
export function ask(title, lines, answers, onEscape = null) {
  const box = byId("ask");
  if (box.open) box.close();
  const buttons = answers.map(([label, action, className = ""]) => button(label, () => { box.close(); action(); }, { className }));
  box.replaceChildren(make("h2", {}, title), ...lines.filter(Boolean).map((line) => make("p", {}, line)),
    make("div", { className: "answers" }, ...buttons));
  box.oncancel = (e) => { if (onEscape) onEscape(); else e.preventDefault(); };
  box.showModal();
  buttons[0].focus();
}

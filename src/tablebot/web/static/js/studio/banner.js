// The banner under the toolbar: a message (good ones fade after 6 s), optional action buttons, a close button.
import { byId, button } from "../lib/dom.js";

let fade = null;

export function banner(text, kind = "", actions = []) {
  const box = byId("banner");
  const hide = () => { box.hidden = true; };
  box.replaceChildren(text);
  box.className = "banner " + kind;
  box.hidden = false;
  for (const [label, action] of actions) box.append(button(label, () => { hide(); action(); }));
  box.append(button("×", hide, { className: "close" }));
  clearTimeout(fade);
  if (kind === "good") fade = setTimeout(hide, 6000);
}

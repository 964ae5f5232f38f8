// Small DOM helpers. User text only ever reaches the page through textContent, never as HTML.

/** The element with this id. */
export const byId = (id) => document.getElementById(id);

/** A new element: `props` are assigned as properties (className, type, title, ...), `children` appended
 * (strings as text). */
export function make(tag, props = {}, ...children) {
  const node = Object.assign(document.createElement(tag), props);
  node.append(...children);
  return node;
}

/** A button that runs `action` when clicked. */
export function button(label, action, props = {}) {
  const node = make("button", { type: "button", ...props }, label);
  node.addEventListener("click", action);
  return node;
}

/** Add `value` to a <select> unless it is there already. */
export function addOption(select, value, label = value) {
  if ([...select.options].some((o) => o.value === value)) return;
  select.append(make("option", { value }, label));
}

/** Every element matching `selector`. */
export const all = (selector) => [...document.querySelectorAll(selector)];

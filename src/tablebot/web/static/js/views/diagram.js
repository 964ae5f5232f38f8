// The state diagram: Graphviz's SVG of the table (made by the server), with the current state highlighted.
// Drawn so that its smallest text is at least 11 px (more with A+), in a view that pans (drag, or scroll) and
// zooms (the − and + buttons, or Ctrl + wheel, as a pinch sends it), following the current state. Enlarged (a
// click, or ⤢) over the part of the page `bigPlace()` gives, never over the arena; Esc or ✕ puts it back.
import { t } from "../lib/words.js";

const MIN_TEXT_PX = 11;
const ZOOMS = [0.35, 0.5, 0.7, 0.85, 1, 1.25, 1.6, 2, 2.5];  // × the readable size

function tool(label, key, action) {  // key: its title's word; made before the page's language is known
  const b = document.createElement("button");
  b.type = "button";
  b.textContent = label;
  b.dataset.tTitle = key;  // said again by translatePage once it is (lib/words.js)
  b.title = t(key);
  b.addEventListener("click", (e) => { e.stopPropagation(); action(); });
  return b;
}

export class Diagram {
  constructor(holder, { bigPlace = null } = {}) {
    this.holder = holder;
    this.bigPlace = bigPlace;  // () => DOMRect to cover when enlarged (null: the stylesheet's place)
    this.nodes = new Map();  // state id (text) -> the node's <g>
    this.current = null;
    this.svg = null;
    this.zoom = ZOOMS.indexOf(1);
    this.view = document.createElement("div");
    this.view.className = "diagram-view";
    this.tools = document.createElement("div");
    this.tools.className = "diagram-tools";
    this.bigButton = tool("⤢", "diagram.enlarge", () => this.setBig(!this.big));
    this.tools.append(tool("−", "diagram.smaller", () => this.zoomBy(-1)), tool("+", "diagram.larger", () => this.zoomBy(1)), this.bigButton);
    holder.replaceChildren(this.view, this.tools);
    this._listen();
    new ResizeObserver(() => this._size()).observe(this.tools);  // the tools grow with A+: so does the text
  }

  get big() { return this.holder.classList.contains("big"); }

  setBig(on) {
    this.holder.classList.toggle("big", on);
    this.bigButton.textContent = on ? "✕" : "⤢";
    this.bigButton.dataset.tTitle = on ? "diagram.back" : "diagram.enlarge";
    this.bigButton.title = t(this.bigButton.dataset.tTitle);
    const box = on && this.bigPlace ? this.bigPlace() : null;
    for (const [side, value] of Object.entries(box ? { left: box.left, top: box.top, width: box.width, height: box.height }
      : { left: null, top: null, width: null, height: null })) this.holder.style[side] = value === null ? "" : value + "px";
    if (box) this.holder.style.right = this.holder.style.bottom = "auto";
    else this.holder.style.right = this.holder.style.bottom = "";
    this._follow(true);
  }

  zoomBy(step) {
    this.zoom = Math.max(0, Math.min(ZOOMS.length - 1, this.zoom + step));
    this._size();
    this._follow(true);
  }

  _listen() {
    let drag = null;
    this.view.addEventListener("pointerdown", (e) => {
      drag = { x: e.clientX, y: e.clientY, left: this.view.scrollLeft, top: this.view.scrollTop, moved: false };
    });
    this.view.addEventListener("pointermove", (e) => {
      if (!drag) return;
      const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
      if (Math.abs(dx) + Math.abs(dy) > 4) drag.moved = true;
      this.view.scrollLeft = drag.left - dx;
      this.view.scrollTop = drag.top - dy;
    });
    this.view.addEventListener("pointerup", () => {
      if (drag && !drag.moved && !this.big) this.setBig(true);  // a click (not a drag) enlarges it
      drag = null;
    });
    this.view.addEventListener("pointerleave", () => { drag = null; });
    this.view.addEventListener("wheel", (e) => {
      if (!e.ctrlKey) return;  // a plain wheel scrolls; Ctrl + wheel (a pinch) zooms
      e.preventDefault();
      this.zoomBy(e.deltaY < 0 ? 1 : -1);
    }, { passive: false });
    document.addEventListener("keydown", (e) => { if (e.key === "Escape" && this.big) this.setBig(false); });
  }

  // svgText comes from Graphviz, which the server gave only escaped labels; it is parsed as SVG
  // (never as HTML) and scripts or event attributes in it would not run under the page's CSP. Text not
  // starting with "<" is the server's sentence saying why there is no diagram (no Graphviz): shown as text.
  setSvg(svgText) {
    this.view.textContent = "";
    this.nodes.clear();
    this.current = null;
    this.svg = null;
    if (!svgText) return;
    if (!svgText.startsWith("<")) {
      const note = document.createElement("p");
      note.className = "diagram-note";
      note.textContent = svgText;
      this.view.appendChild(note);
      return;
    }
    const parsed = new DOMParser().parseFromString(svgText, "image/svg+xml").documentElement;
    if (parsed.nodeName !== "svg") return;
    const svg = document.importNode(parsed, true);
    this._measure(svg);
    this.view.appendChild(svg);
    this.svg = svg;
    for (const g of this.view.querySelectorAll("g.node")) {
      const title = g.querySelector("title");
      if (title && title.textContent.startsWith("s_")) this.nodes.set(title.textContent.slice(2), g);
    }
    this._size();
    this.view.scrollTop = 0;  // its top (where it starts), centred: until a state is lit
    this.view.scrollLeft = (this.view.scrollWidth - this.view.clientWidth) / 2;
  }

  // The drawing's own size (its viewBox) and its smallest text, in its units.
  _measure(svg) {
    const box = svg.viewBox.baseVal;
    this.width = box && box.width ? box.width : parseFloat(svg.getAttribute("width")) || 400;
    this.height = box && box.height ? box.height : parseFloat(svg.getAttribute("height")) || 300;
    const sizes = [...svg.querySelectorAll("text")].map((text) => parseFloat(text.getAttribute("font-size")) || 14);
    this.minFont = sizes.length ? Math.min(...sizes) : 14;
    svg.removeAttribute("width"); svg.removeAttribute("height");
  }

  /** Size the drawing: its smallest text 11 px at the page's text size (A+ makes it larger), × the zoom. */
  _size() {
    if (!this.svg) return;
    const pagePx = parseFloat(getComputedStyle(document.body).fontSize) / 14;
    const scale = MIN_TEXT_PX * 1.001 / this.minFont * Math.max(1, pagePx) * ZOOMS[this.zoom];  // (not 10.9999)
    this.svg.style.width = this.width * scale + "px";
    this.svg.style.height = this.height * scale + "px";
  }

  highlight(stateId) {
    if (stateId === this.current) return;
    if (this.current !== null && this.nodes.has(this.current)) this.nodes.get(this.current).classList.remove("current");
    this.current = stateId;
    const node = this.nodes.get(stateId);
    if (node) node.classList.add("current");
    this._follow(false);
  }

  // Keep the current state in view (centred when it is out of view, or when `always`).
  _follow(always) {
    const node = this.nodes.get(this.current);
    if (!node) return;
    const view = this.view.getBoundingClientRect(), at = node.getBoundingClientRect();
    const inside = at.left >= view.left && at.right <= view.right && at.top >= view.top && at.bottom <= view.bottom;
    if (inside && !always) return;
    this.view.scrollLeft += at.left + at.width / 2 - (view.left + view.width / 2);
    this.view.scrollTop += at.top + at.height / 2 - (view.top + view.height / 2);
  }
}

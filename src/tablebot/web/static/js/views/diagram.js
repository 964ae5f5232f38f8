// The state diagram: Graphviz's SVG of the table (made by the server), with the current state highlighted.

export class Diagram {
  constructor(holder) {
    this.holder = holder;
    this.nodes = new Map();  // state id (text) -> the node's <g>
    this.current = null;
    holder.addEventListener("click", () => holder.classList.toggle("big"));
  }

  // svgText comes from Graphviz, which the server gave only escaped labels; it is parsed as SVG
  // (never as HTML) and scripts or event attributes in it would not run under the page's CSP. Text not
  // starting with "<" is the server's sentence saying why there is no diagram (no Graphviz): shown as text.
  setSvg(svgText) {
    this.holder.textContent = "";
    this.nodes.clear();
    this.current = null;
    if (!svgText) return;
    if (!svgText.startsWith("<")) {
      const note = document.createElement("p");
      note.className = "diagram-note";
      note.textContent = svgText;
      this.holder.appendChild(note);
      return;
    }
    const svg = new DOMParser().parseFromString(svgText, "image/svg+xml").documentElement;
    if (svg.nodeName !== "svg") return;
    svg.removeAttribute("width"); svg.removeAttribute("height");
    svg.setAttribute("preserveAspectRatio", "xMidYMin meet");
    this.holder.appendChild(document.importNode(svg, true));
    for (const g of this.holder.querySelectorAll("g.node")) {
      const title = g.querySelector("title");
      if (title && title.textContent.startsWith("s_")) this.nodes.set(title.textContent.slice(2), g);
    }
  }

  highlight(stateId) {
    if (stateId === this.current) return;
    if (this.current !== null && this.nodes.has(this.current)) this.nodes.get(this.current).classList.remove("current");
    this.current = stateId;
    const node = this.nodes.get(stateId);
    if (node) node.classList.add("current");
  }
}

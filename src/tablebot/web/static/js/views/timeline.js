// A timeline strip: the state at each tick as a coloured band, and a cursor; click or drag to seek.

export class Timeline {
  constructor(canvas, colourOf, onSeek) {
    this.canvas = canvas;
    this.colourOf = colourOf;  // state id -> colour
    this.states = [];  // state id per tick
    this.cursor = 0;
    this.onSeek = onSeek;
    canvas.addEventListener("pointerdown", (e) => this._seek(e));
    canvas.addEventListener("pointermove", (e) => { if (e.buttons) this._seek(e); });
    new ResizeObserver(() => this.draw()).observe(canvas);
  }

  setStates(states) { this.states = states; this.draw(); }

  setCursor(index) { this.cursor = index; this.draw(); }

  _seek(e) {
    if (!this.states.length) return;
    const box = this.canvas.getBoundingClientRect();
    const index = Math.round((e.clientX - box.left) / box.width * (this.states.length - 1));
    this.onSeek(Math.max(0, Math.min(this.states.length - 1, index)));
  }

  draw() {
    const c = this.canvas, ratio = window.devicePixelRatio || 1, box = c.getBoundingClientRect();
    c.width = Math.max(10, box.width * ratio); c.height = Math.max(10, box.height * ratio);
    const g = c.getContext("2d"), n = this.states.length, W = c.width, H = c.height;
    g.fillStyle = "#f1f3f5"; g.fillRect(0, 0, W, H);
    if (!n) return;
    for (let px = 0; px < W; px++) {  // one pixel column per bucket of ticks
      g.fillStyle = this.colourOf(this.states[Math.min(n - 1, Math.floor(px / W * n))]);
      g.fillRect(px, 0, 1, H * 0.78);
    }
    const x = (n > 1 ? this.cursor / (n - 1) : 0) * (W - 2) + 1;
    g.fillStyle = "#000"; g.fillRect(x - ratio, 0, 2 * ratio, H);
  }
}

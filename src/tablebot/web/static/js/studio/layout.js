// The page's layout, fitted to the window, the text size (A−/A+) and the table: every column of the table in
// view without scrolling sideways, and the arena and the checks always on the screen. The first that fits, of:
// the table beside the robot ("side"), then the same with a compact grid, then the table across the top with
// the checks, the arena and the machine under it ("stack"), then that with a compact grid.

const CHOICES = [["side", false], ["side", true], ["stack", false], ["stack", true]];
const MIN_RIGHT_EM = 25;  // the arena and its controls beside the table: narrower, and they are too small to use

function needs(table, holder) {
  // the grid's own width, its border and its vertical scroll bar
  return table.getBoundingClientRect().width + (holder.offsetWidth - holder.clientWidth);
}

function fits(layout, need, main, fontPx) {
  const style = getComputedStyle(main);
  const inner = main.clientWidth - parseFloat(style.paddingLeft) - parseFloat(style.paddingRight);
  if (layout === "stack") return need <= inner;
  return inner - need - parseFloat(style.columnGap) >= MIN_RIGHT_EM * fontPx;
}

// The toolbar on one line if leaving out the name and the word "table" does it (a tablet, A+).
function fitBar(body) {
  const bar = document.querySelector(".bar");
  const wrapped = () => {
    const shown = [...bar.children].filter((el) => el.offsetParent !== null);
    return shown.some((el) => el.offsetTop > shown[0].offsetTop + el.offsetHeight / 2);
  };
  body.classList.remove("tight-bar");
  if (bar && wrapped()) body.classList.add("tight-bar");
}

/** Choose the layout for the window as it is now (called when the window, the text size or the table change). */
export function fitLayout() {
  const body = document.body, main = document.querySelector("main");
  fitBar(body);
  const table = document.querySelector("#grid table.grid"), holder = document.querySelector("#grid");
  if (!table || !main) return;
  const fontPx = parseFloat(getComputedStyle(body).fontSize);
  let chosen = CHOICES[CHOICES.length - 1], width = 0;
  for (const [layout, compact] of CHOICES) {
    body.dataset.layout = layout;
    body.classList.toggle("compact", compact);
    width = needs(table, holder);
    if (fits(layout, width, main, fontPx)) { chosen = [layout, compact]; break; }
  }
  body.dataset.layout = chosen[0];
  body.classList.toggle("compact", chosen[1]);
  if (chosen[0] === "side") main.style.setProperty("--left", Math.ceil(needs(table, holder)) + "px");
  else main.style.removeProperty("--left");
}

/** Fit the layout now and whenever the window or the table's size changes (a cell typed wider, A+). */
export function keepFitted() {
  let queued = false;
  const again = () => {
    if (queued) return;
    queued = true;
    requestAnimationFrame(() => { queued = false; fitLayout(); });
  };
  window.addEventListener("resize", again);
  const watch = new ResizeObserver(again);
  new MutationObserver(() => {  // the grid is drawn anew when a table opens
    const table = document.querySelector("#grid table.grid");
    if (table) { watch.disconnect(); watch.observe(table); again(); }
  }).observe(document.querySelector("#grid"), { childList: true });
  return again;
}

// What the page's own buttons, menus and keys do: each sends a message or changes the store.
import { all, byId } from "../lib/dom.js";
import { askForLink } from "./sharebox.js";
import { api } from "../lib/key.js";
import { percent, t } from "../lib/words.js";

const on = (id, type, handler) => byId(id).addEventListener(type, handler);

function wireTable(store, send, drafts) {
  on("save", "click", () => send({ op: "save" }));
  on("share", "click", () => send({ op: "share" }));
  on("open-link", "click", () => askForLink(send));
  on("table-pick", "change", (e) => {
    const { dirty, path } = store.get();
    if (dirty && !confirm(t("open.unsaved"))) { e.target.value = path; return; }
    if (dirty) drafts.drop(path, true);  // the user chose to lose them
    store.set({ offerDraft: e.target.value });
    send({ op: "open", path: e.target.value });
  });
  on("add-row", "click", () => {
    const { selectedRow } = store.get();
    send({ op: "insert_row", after: selectedRow === null ? byId("grid").querySelectorAll("tbody tr").length - 1 : selectedRow });
  });
  on("del-row", "click", () => {
    const { selectedRow } = store.get();
    if (selectedRow !== null) send({ op: "delete_row", row: selectedRow });
  });
  document.addEventListener("keydown", (e) => {
    if ((e.ctrlKey || e.metaKey) && e.key === "s") {
      e.preventDefault();
      if (store.get().path && store.get().dirty) send({ op: "save" });  // nothing to save: nothing done
    }
  });
  window.addEventListener("beforeunload", (e) => {
    if (store.get().dirty) { e.preventDefault(); e.returnValue = ""; }
  });
}

function wireLive(store, send) {
  on("mode-live", "click", () => store.set({ mode: "live" }));
  on("mode-trace", "click", () => store.set({ mode: "trace" }));
  on("play", "click", () => send({ op: "sim", action: store.get().paused ? "play" : "pause" }));
  on("step", "click", () => send({ op: "sim", action: "step" }));
  for (const b of all("[data-speed]")) b.addEventListener("click", () => send({ op: "sim", action: "speed", speed: b.dataset.speed }));
  for (const b of all("[data-click]")) b.addEventListener("click", () => store.set({ clickMode: b.dataset.click }));
  const reset = () => send({ op: "sim", action: "reset", seed: Math.max(0, parseInt(byId("seed").value, 10) || 0),
    charge: +byId("battery").value / 100 });
  on("battery", "input", () => { byId("battery-text").textContent = percent(byId("battery").value / 100); });
  on("battery", "change", reset);
  on("reset", "click", reset);
}

// A trace from the folder (over the WebSocket) or from the user's computer (uploaded).
function wireTraces(send, receive) {
  on("trace-pick", "change", (e) => { if (e.target.value) send({ op: "trace", path: e.target.value }); });
  on("trace-file", "change", async (e) => {
    const file = e.target.files[0];
    if (!file) return;
    const reply = await api("/api/trace?name=" + encodeURIComponent(file.name), { method: "POST", body: file });
    const json = (reply.headers.get("content-type") || "").startsWith("application/json");
    receive(json ? await reply.json() : { type: "error", message: await reply.text() });
  });
}

export function wireControls(store, send, receive, drafts) {
  wireTable(store, send, drafts);
  wireLive(store, send);
  wireTraces(send, receive);
}

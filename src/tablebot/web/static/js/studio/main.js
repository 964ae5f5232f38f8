// The studio page: one store, one WebSocket, the views and panels wired to them.
import { byId } from "../lib/dom.js";
import { api } from "../lib/key.js";
import { createStore } from "../lib/store.js";
import { chooseLanguage, currentLanguage, setLanguage, t, translatePage, wireSwitch } from "../lib/words.js";
import { wirePlayerControls, wireZoom } from "../views/player.js";
import { banner } from "./banner.js";
import { wireControls } from "./controls.js";
import { createDrafts } from "./drafts.js";
import { keepFitted } from "./layout.js";
import { createLink } from "./link.js";
import { messageHandlers } from "./messages.js";
import { checkedLink } from "./protocol.js";
import { showNoTable, showPanels } from "./panels.js";
import { openLinkInAddress } from "./sharebox.js";
import { stats } from "./stats.js";
import { createViews } from "./views.js";

const store = createStore({
  path: null, files: { tables: [], traces: [] }, machine: null, analysis: null, seq: 0, editSent: 0,
  mode: "live", frame: null, clickMode: "start", speed: "1", paused: true, held: {}, runError: null,
  world: null, tickMs: 10, dirty: null /* no table yet: neither saved nor not */, selectedRow: null, mask: undefined, why: [], arenaOk: false,
  cex: null /* a counterexample playing in the arena */, folder: "", version: null /* of the file the draft started from */, offerDraft: null /* the table whose kept draft to offer */,
});
const link = checkedLink(createLink());  // what the page sends is an operation of the protocol
let drafts = null;
const views = createViews(store, link.send, () => drafts.keep());
drafts = createDrafts(store, views.grid);
const handlers = messageHandlers(store, views, link.send, drafts);
const receive = (m) => { if (handlers[m.type]) handlers[m.type](m); };

showPanels(store, views, link.send);
wireControls(store, link.send, receive, drafts);
wirePlayerControls(views.player);
wireZoom(views.arena);
keepFitted();

views.arena.onDrawn = (ms) => { stats.drawMs = ms; };  // the arena draws itself when it changes

async function start() {
  const params = new URLSearchParams(location.search);  // without the token (../lib/key.js took it)
  const reply = await api("/api/config");
  if (!reply.ok) { banner(await reply.text(), "bad"); return; }
  const config = await reply.json();
  setLanguage(chooseLanguage(config.lang));  // before any word is shown, and before the server is told it
  translatePage();
  wireSwitch(byId("language"));
  store.set({ files: config, folder: config.folder });
  const wanted = params.get("table") || config.table || config.tables[0];
  if (!wanted) showNoTable(config, link.send);
  // each connection opens the table, and offers back the edits this browser kept of it
  const hello = () => {
    const path = store.get().path || wanted;
    store.set({ offerDraft: path || null });
    return path ? { op: "open", path } : null;
  };
  openLinkInAddress(link.send);  // sent once the connection is up (after the table it opens first)
  link.open(hello, currentLanguage(), receive, { down: connectionDown, up: () => banner(t("link.again"), "good") });
}

function connectionDown(tries) {
  const kept = store.get().dirty ? " " + t("link.kept") : "";
  banner(t(tries < 3 ? "link.lost" : "link.gone") + kept, "bad");
}

views.arena.invalidate();
start();

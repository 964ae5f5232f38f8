// Unsaved edits kept in this browser (localStorage, by folder and table), so that a dropped connection, a
// reload or a studio restarted on the same port does not lose them: kept at every edit, offered back when
// the table is opened again, dropped when saved or when the user chooses to drop them.
const PREFIX = "tablebot-draft:";

// This tab's name, kept across its reloads (sessionStorage): a save drops only a draft this tab kept.
function tabName() {
  try {
    let name = sessionStorage.getItem("tablebot-tab");
    if (!name) { name = Math.random().toString(36).slice(2); sessionStorage.setItem("tablebot-tab", name); }
    return name;
  } catch { return "tab"; }
}

function read(key) {
  try { return JSON.parse(localStorage.getItem(key)); } catch { return null; }
}

/** The drafts of the folder in `store` (its `folder`, `path` and `version`), taken from `grid`. */
export function createDrafts(store, grid) {
  const tab = tabName();
  const key = (path) => PREFIX + store.get().folder + "/" + path;

  /** Keep the grid as the open table's draft (the version it started from, the time, this tab). */
  function keep() {
    const { path, version } = store.get();
    if (!path || !grid.header) return;
    const draft = { path, base: version, header: grid.header, grid: grid.values, at: Date.now(), tab };
    try { localStorage.setItem(key(path), JSON.stringify(draft)); } catch { /* full or off: the server still holds it */ }
  }

  /** Forget the draft of `path`: one this tab kept, or (`anyTab`) whoever kept it. */
  function drop(path, anyTab = false) {
    const draft = read(key(path));
    if (draft && (anyTab || draft.tab === tab)) localStorage.removeItem(key(path));
  }

  /** The draft of `path` to offer back, if it differs from the table as loaded (`header`, `rows`). */
  function waiting(path, header, rows) {
    const draft = read(key(path));
    if (!draft || !Array.isArray(draft.grid) || !Array.isArray(draft.header)) return null;
    if (JSON.stringify([draft.header, draft.grid]) === JSON.stringify([header, rows])) { drop(path, true); return null; }
    return draft;
  }

  return { keep, drop, waiting };
}

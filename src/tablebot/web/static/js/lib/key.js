// The studio's key (its token), kept where no other port's page can reach it. It comes once, in the address
// the studio printed (/?token=...); it is kept in sessionStorage, which belongs to this origin (so this
// port) and this tab, and kept across its reloads; and it is taken out of the address bar and history at
// once. No cookie: a browser sends a 127.0.0.1 cookie to every port of 127.0.0.1, so any server there
// would receive it. The key goes with every API request (a header) and with the WebSocket (a subprotocol:
// a browser's WebSocket can set no header), and the server checks it before anything else.
const NAME = "tablebot-studio-token";
const HEADER = "X-Tablebot-Token";
const SHAPE = /^[A-Za-z0-9_-]{1,200}$/;  // what the studio makes (secrets.token_urlsafe)
let held = "";  // when sessionStorage is off (a private window's setting): kept until the page goes

function takeFromAddress() {
  const params = new URLSearchParams(location.search);
  if (!params.has("token")) return;
  const given = params.get("token");
  held = SHAPE.test(given) ? given : "";  // a mangled address: no key (a header or subprotocol could not carry it)
  try { sessionStorage.setItem(NAME, held); } catch { /* storage off: held for this page only */ }
  params.delete("token");
  history.replaceState(history.state, "", location.pathname + (params.toString() ? "?" + params : "") + location.hash);
}

/** The key this tab holds ("" when it has none: the server's refusal then says how to get in). */
export function key() {
  try { return sessionStorage.getItem(NAME) || held; } catch { return held; }
}

/** fetch() of one of the studio's own addresses, with the key. */
export function api(path, init = {}) {
  const headers = new Headers(init.headers || {});
  headers.set(HEADER, key());
  return fetch(path, { ...init, headers });
}

/** A WebSocket to the studio's `path`, with the key. */
export function socketTo(path) {
  const url = (location.protocol === "https:" ? "wss://" : "ws://") + location.host + path;
  return new WebSocket(url, ["tablebot-studio", "tablebot-token." + key()]);
}

takeFromAddress();  // as this module loads, before any other of the page's code runs

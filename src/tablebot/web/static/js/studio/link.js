// The page's one WebSocket to the studio server, reconnected when it drops. Messages sent before it first
// opens wait in a queue; messages sent while it is down are dropped (the edits among them are in the page's
// draft, offered back once it is up again). The studio's key goes with each connection (../lib/key.js).
import { socketTo } from "../lib/key.js";
import { stats } from "./stats.js";

const RETRY_MS = [1000, 2000, 4000, 8000];  // then every 10 s

export function createLink() {
  const pending = [];
  const link = { socket: null, opened: false /* it was open once: a new connection is a reconnect */ };

  function send(message) {
    if (link.socket && link.socket.readyState === WebSocket.OPEN) link.socket.send(JSON.stringify(message));
    else if (!link.opened) pending.push(message);
  }

  /** Connect, and again whenever it drops, telling the server the page's language (`lang`: it says its errors
   * and findings in it): `hello(again)` gives the first message of each connection (if
   * any), each reply goes to `receive`; `down(tries)` and `up()` tell the page it dropped and came back. */
  function open(hello, lang, receive, { down, up }) {
    let tries = 0;
    const connect = () => {
      const socket = link.socket = socketTo("/ws?lang=" + encodeURIComponent(lang));
      socket.addEventListener("open", () => {
        const again = link.opened;
        const first = hello(again);
        if (first) socket.send(JSON.stringify(first));
        while (pending.length) socket.send(JSON.stringify(pending.shift()));
        link.opened = true;
        tries = 0;
        if (again) up();
      });
      socket.addEventListener("message", (e) => { stats.messages += 1; receive(JSON.parse(e.data)); });
      socket.addEventListener("close", () => { down(tries); setTimeout(connect, RETRY_MS[tries++] || 10000); });
    };
    connect();
  }

  return { send, open };
}

// The page's one WebSocket to the studio server. Messages sent before it is open wait in a queue; the
// token travels in the page's HttpOnly cookie, never in the address or a message.
import { stats } from "./stats.js";

export function createLink() {
  const pending = [];
  let socket = null;

  function send(message) {
    if (socket && socket.readyState === WebSocket.OPEN) socket.send(JSON.stringify(message));
    else pending.push(message);
  }

  /** Connect; `first` (if any) goes before the queued messages, each reply to `receive`. */
  function open(first, receive, onClose) {
    socket = new WebSocket((location.protocol === "https:" ? "wss://" : "ws://") + location.host + "/ws");
    socket.addEventListener("open", () => {
      if (first) socket.send(JSON.stringify(first));
      while (pending.length) socket.send(JSON.stringify(pending.shift()));
    });
    socket.addEventListener("message", (e) => { stats.messages += 1; receive(JSON.parse(e.data)); });
    socket.addEventListener("close", onClose);
  }

  return { send, open };
}

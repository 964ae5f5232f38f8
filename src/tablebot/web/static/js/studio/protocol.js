// The studio's WebSocket protocol as the page sees it: every operation the page sends (`op`) with its fields,
// and every kind of message (`type`) the server sends back. The server's side is tablebot/web/protocol.py;
// tests/web/test_studio_protocol.py imports this module under Node and holds the two equal.

/** The operations the page may send, each with the fields it may carry. */
export const OPERATIONS = Object.freeze({
  open: ["path"],
  edit: ["row", "col", "value", "seq"],
  insert_row: ["after", "seq"],
  delete_row: ["row", "seq"],
  save: ["force"],
  restore: ["header", "grid", "base", "seq"],
  // the arena's robot: play, pause, step, speed, hold, script or reset, with that action's fields
  sim: ["action", "speed", "input", "on", "masks", "seed", "charge", "start", "lamp", "paused"],
  trace: ["path"],
  counterexample: ["name", "where"],
  files: [],
  new: ["template", "name"],  // a robot from a `tablebot new` template, in a folder without a table
  share: [],
  open_link: ["link"],  // a share link pasted in the page or in its address: its table, in a new folder  // a link carrying the table as edited, and its QR code
});

/** The kinds of message the server sends, which the page handles (messages.js, one handler each). */
export const MESSAGES = Object.freeze(["table", "grid", "analysis", "diagram", "arena", "control", "frame", "trace",
  "files", "saved", "conflict", "notice", "error", "shared"]);

/** `message` if it is an operation of the protocol with only its fields; anything else throws, so a mistake
 * in the page shows in the console where it was made instead of as the server's "unknown op". */
export function checkedOperation(message) {
  const fields = OPERATIONS[message.op];
  if (!Object.hasOwn(OPERATIONS, message.op)) throw new Error(`not an operation of the studio: ${message.op}`);
  const extra = Object.keys(message).filter((key) => key !== "op" && !fields.includes(key));
  if (extra.length) throw new Error(`${message.op} has no field ${extra.join(", ")}`);
  return message;
}

/** The link with its `send` checked (checkedOperation) before anything is sent. */
export function checkedLink(link) {
  return { ...link, send: (message) => link.send(checkedOperation(message)) };
}

/** `handlers` (one per message kind) when they are exactly one for each kind in MESSAGES; else it throws. */
export function byKind(handlers) {
  const kinds = Object.keys(handlers).sort();
  const expected = [...MESSAGES].sort();
  if (kinds.join() !== expected.join()) throw new Error(`handlers for ${kinds.join(", ")}; the protocol has ${expected.join(", ")}`);
  return handlers;
}

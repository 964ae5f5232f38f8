// The fixed module beside a machine config written by `tablebot export --to xstate` (docs/statecharts.md).
// It implements the config's named guards and actions for XState 5 and runs one tick per `tick` event:
//
//   import { createActor } from "xstate";
//   import { tablebotMachine, tick } from "./tablebot-xstate.mjs";
//   const actor = createActor(tablebotMachine(config)).start();
//   tick(actor, { I3: 1, I4: 0 }, { C1: 2 });   // each input 0 or 1, each counter's pulses (sent as C1_pulses)
//   actor.getSnapshot().value, actor.getSnapshot().context.M1
//
// The tick model: the root's `tick` transition counts the timers and counters down (not on the first tick), sets
// the event flags and each table's `pending`; then each table's eventless (`always`) transitions fire the first
// row whose guard holds, or the idle transition last in every state, and clear `pending`. Named guards see the
// context and the event, not the state (statelyai/xstate, packages/core/src/guards.ts, evaluateGuard), so a row's
// cross-table events become XState's own `stateIn` guards here, with `and`/`or`, when the machine is made.
import { and, assign, or, setup, stateIn } from "xstate";

export const guards = {
  // pending, and every flag the row requires; cross-table events and the document's "some event" are
  // added by tablebotMachine as stateIn guards beside this one
  row: ({ context }, params) => {
    if (params.cross.length > 0 || params.some !== null) {
      throw new Error("a row with cross-table events: make the machine with tablebotMachine(config)");
    }
    return context[params.pending] === 1 && params.flags.every((flag) => context[flag] === true);
  },
  // some flag of the table is set (the document's rule for a row that requires no event)
  someFlag: ({ context }, params) => params.flags.some((flag) => context[flag] === true),
  idle: ({ context }, params) => context[params.pending] === 1,
};

function countDown(context, event, params) {
  const next = { [params.started]: 1 };
  if (context[params.started] === 1) {
    for (const table of params.tables) {
      next[table.timer] = Math.max(0, context[table.timer] - 1);
    }
    for (const counter of params.counters) {
      next[counter.name] = Math.max(0, context[counter.name] - event[counter.pulses]);
    }
  }
  const value = (name) => (name in next ? next[name] : context[name]);
  for (const input of params.inputs) {
    next[`has_${input}`] = event[input] === 1;
  }
  for (const counter of params.counters) {
    next[`has_${counter.name}`] = value(counter.name) === 0;
  }
  for (const table of params.tables) {
    next[table.flag] = value(table.timer) === 0;
    next[table.pending] = 1;
  }
  return next;
}

export const actions = {
  tick: assign(({ context, event }, params) => countDown(context, event, params)),
  fire: assign((_, params) => ({
    ...params.set,
    [params.timer]: params.load,
    [params.row]: params.index,
    [params.pending]: 0,
  })),
  idle: assign((_, params) => ({ [params.row]: -1, [params.pending]: 0 })),
};

function present(cross) {
  return or(cross.in.map((value) => stateIn(value)));
}

// A row's guard as XState evaluates it: the named guard, and stateIn for each cross-table event it requires
function rowGuard(guard) {
  const { cross, some } = guard.params;
  if (cross.length === 0 && some === null) {
    return guard;
  }
  const named = { type: "row", params: { ...guard.params, cross: [], some: null } };
  const parts = [named, ...cross.map(present)];
  if (some !== null) {
    parts.push(or([{ type: "someFlag", params: { flags: some.flags } }, ...some.cross.map(present)]));
  }
  return and(parts);
}

function hydrate(node) {
  const states = Object.fromEntries(
    Object.entries(node.states ?? {}).map(([key, child]) => [key, hydrate(child)]),
  );
  const always = node.always?.map((transition) => (
    transition.guard?.type === "row" ? { ...transition, guard: rowGuard(transition.guard) } : transition
  ));
  return { ...node, ...(node.states ? { states } : {}), ...(always ? { always } : {}) };
}

export function tablebotMachine(config) {
  return setup({ guards, actions }).createMachine(hydrate(config));
}

export function tick(actor, inputs, pulses = {}) {
  const counts = Object.fromEntries(Object.entries(pulses).map(([name, count]) => [`${name}_pulses`, count]));
  actor.send({ type: "tick", ...inputs, ...counts });
}

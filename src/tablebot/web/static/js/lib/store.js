// The page's state in one place: views subscribe to the keys they draw and are called when one changes.

/** A store holding `initial`; `set` merges a patch and calls each subscriber of a changed key once. */
export function createStore(initial) {
  let state = { ...initial };
  const listeners = new Map();  // key -> Set of functions

  function set(patch) {
    const changed = Object.keys(patch).filter((key) => state[key] !== patch[key]);
    if (!changed.length) return;
    state = { ...state, ...patch };
    const called = new Set();
    for (const key of changed) {
      for (const listener of listeners.get(key) || []) {
        if (!called.has(listener)) { called.add(listener); listener(state); }
      }
    }
  }

  function on(keys, listener) {
    for (const key of keys) {
      if (!listeners.has(key)) listeners.set(key, new Set());
      listeners.get(key).add(listener);
    }
  }

  return { get: () => state, set, on };
}

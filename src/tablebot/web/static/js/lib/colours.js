// Each state's colour, as the server gave it (tablebot.colours, the same as in every PNG of the table):
// the page only looks it up, by state id, in the machine the store holds.

const NONE = "#999999";  // a state the table does not have (a trace of another table, or no state)
const byMachine = new WeakMap();  // machine -> Map(state id -> colour)

/** A function from a state id to its colour, read from the store's current `machine`. */
export function stateColours(store) {
  return (id) => {
    const machine = store.get().machine;
    if (!machine) return NONE;
    if (!byMachine.has(machine)) byMachine.set(machine, new Map(machine.states.map((s) => [s.id, s.colour])));
    return byMachine.get(machine).get(String(id)) || NONE;
  };
}

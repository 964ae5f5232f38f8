"""Checking properties exhaustively: prove them on the abstract model, or find the shortest real run
that breaks them and turn it into an inputs CSV that ``tablebot trace`` replays.

Each property becomes a small monitor that reads one tick at a time (the same ticks a trace
records). Breadth-first search over (model node, monitor state) visits every reachable pair, so
"no violation found" is a proof; the first violation found is a shortest one. Proofs use the
abstract model (sound); violations are searched again in the exact model, so a reported
counterexample is real and shortest in ticks, and it is confirmed by replaying it on the engine.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any

from tablebot.analysis.conditions import Obs
from tablebot.analysis.model import Graph, Model, ModelTooLarge, Node, Tick, walk_back
from tablebot.analysis.properties import Property
from tablebot.formats.inputs_csv import TickInput
from tablebot.i18n import N_
from tablebot.machine import NO_ROW, Machine
from tablebot.replay import replay

VIOLATION = None  # a monitor step returning this means the property is broken at this tick
EXACT_BUDGET = 300_000  # about 2-3 s of searching before falling back
Path = list[tuple[Node, Tick]]


@dataclass
class Result:
    """The outcome for one property: ``holds``, ``violated`` or ``unknown``."""

    prop: Property
    status: str
    explored: int = 0
    inputs: list[TickInput] = field(default_factory=list)  # counterexample, or witness of `reachable`
    at_tick: int | None = None  # the tick of the replayed inputs where it shows
    state: Any = None  # `always_reachable`: the state from which the condition is lost for good
    exact: bool = True  # whether the inputs came from the exact model (shortest in ticks)
    detail: str = ""

    @property
    def failed(self) -> bool:
        return self.status != "holds"


# --- monitors ---------------------------------------------------------------------------------------


class Monitor:
    """Reads ticks; ``step`` returns the next monitor state or VIOLATION."""

    start: Any = 0

    def step(self, state: Any, obs: Obs) -> Any:
        raise NotImplementedError


class Never(Monitor):
    def __init__(self, bad: Any) -> None:
        self.bad = bad

    def step(self, state: Any, obs: Obs) -> Any:
        return VIOLATION if self.bad(obs) else 0


class Respond(Monitor):
    """State: age in ticks of the oldest trigger still waiting for ``then`` (-1: none waiting)."""

    start = -1

    def __init__(self, when: Any, then: Any, within: int) -> None:
        self.when, self.then, self.within = when, then, within

    def step(self, age: Any, obs: Obs) -> Any:
        if age >= 0:
            age += 1
        if self.then(obs):
            return -1  # one `then` answers every trigger still waiting
        if age < 0 and self.when(obs):
            age = 0
        if age >= 0 and age >= self.within:
            return VIOLATION  # the oldest trigger has waited its whole window in vain
        return age


def monitor_of(prop: Property) -> Monitor:
    if prop.kind in ("never", "reachable"):
        return Never(prop.cond)
    if prop.kind == "always":
        cond = prop.cond
        return Never(lambda obs: not cond(obs))  # type: ignore[misc]
    if prop.kind == "when":
        return Respond(prop.when, prop.then, prop.within)
    raise ValueError(prop.kind)


def first_violation(prop: Property, machine: Machine, lines: Iterable[dict[str, Any]]) -> int | None:
    """Run the property's monitor over trace lines: the tick where it is broken (or reached)."""
    monitor = monitor_of(prop)
    state = monitor.start
    for line in lines:
        state = monitor.step(state, obs_of_line(machine, line))
        if state is VIOLATION:
            return int(line["tick"])
    return None


def obs_of_line(machine: Machine, line: dict[str, Any]) -> Obs:
    row = NO_ROW if line["row"] is None else int(line["row"])
    return (
        int(line["event"]),
        row,
        machine.states.index(line["state"]),
        tuple(int(line[name]) for name in machine.output_names),
    )


# --- search -----------------------------------------------------------------------------------------


def search(model: Model, monitor: Monitor, budget: int = 10_000_000) -> tuple[Path | None, int]:
    """Breadth-first over (node, monitor state): the shortest path to a violation, and pairs visited."""
    start = (model.initial(), monitor.start)
    parent: dict[tuple[Node, Any], tuple[tuple[Node, Any], Tick] | None] = {start: None}
    queue = deque([start])
    while queue:
        key = queue.popleft()
        node, mstate = key
        for tick in model.successors(node):
            after = tick[3]
            nxt = monitor.step(mstate, (tick[0], tick[2], after[0], after[3]))
            if nxt is VIOLATION:
                return [*_path(parent, key), (node, tick)], len(parent)
            pair = (after, nxt)
            if pair not in parent:
                parent[pair] = (key, tick)
                queue.append(pair)
                if len(parent) > budget:
                    raise ModelTooLarge(N_("more than {budget} situations", budget=budget))
    return None, len(parent)


def _path(parent: dict, key: Any) -> Path:
    """The model steps to a (node, monitor state) pair."""
    return [(pair[0], tick) for pair, tick in walk_back(parent, key)]


def trapped(graph: Graph, good: Any) -> tuple[Path | None, set[Node]]:
    """For ``always_reachable``: nodes from which no tick satisfying ``good`` can ever come, and a
    shortest path to one of them."""
    model = graph.model
    preds: dict[Node, list[Node]] = {n: [] for n in graph.nodes}
    alive: set[Node] = set()
    for node, tick in graph.ticks():
        after = tick[3]
        preds[after].append(node)
        if good((tick[0], tick[2], after[0], after[3])):
            alive.add(node)
    queue = deque(alive)
    while queue:
        for prev in preds[queue.popleft()]:
            if prev not in alive:
                alive.add(prev)
                queue.append(prev)
    dead = {n for n in graph.nodes if n not in alive}
    if not dead:
        return None, dead
    start = model.initial()
    if start in dead:
        return [], dead
    parent: dict[Node, tuple[Node, Tick] | None] = {start: None}
    queue2 = deque([start])
    while queue2:
        node = queue2.popleft()
        for tick in model.successors(node):
            after = tick[3]
            if after in parent:
                continue
            parent[after] = (node, tick)
            if after in dead:
                return walk_back(parent, after), dead
            queue2.append(after)
    return None, dead


# --- checking ---------------------------------------------------------------------------------------


def check_property(prop: Property, machine: Machine, budget: int = EXACT_BUDGET) -> Result:
    """Prove ``prop`` or find its shortest counterexample (for ``reachable``: its shortest witness)."""
    if prop.kind == "always_reachable":
        return _check_always_reachable(prop, machine, budget)
    model = Model(machine, prop.horizon, prop.watch)
    try:
        path, explored = search(model, monitor_of(prop))
    except ModelTooLarge as exc:
        detail = (
            N_("too large to search ({reason}); a shorter within makes it smaller", reason=exc.args[0])
            if prop.kind == "when"
            else N_(
                "too large to search ({reason}); a condition that reads fewer inputs makes it smaller",
                reason=exc.args[0],
            )
        )
        return Result(prop, "unknown", detail=detail)
    reachable = prop.kind == "reachable"
    if path is None:
        status = "violated" if reachable else "holds"
        return Result(prop, status, explored, detail=NEVER if reachable else "")
    exact = model if model.is_exact else Model.exact(machine, prop.watch)
    try:
        if exact is not model:
            path, _ = search(exact, monitor_of(prop), budget)
        if path is None:  # the abstraction was too coarse about when a long timer runs out
            return Result(prop, "violated" if reachable else "holds", explored)
        return _confirmed(prop, machine, exact, path, explored, reachable, exact=True)
    except ModelTooLarge:
        assert path is not None  # search raised before replacing the path found above, or found one (None returned)
        return _confirmed(prop, machine, model, path, explored, reachable, exact=False)


def _confirmed(
    prop: Property, machine: Machine, model: Model, path: Path, explored: int, reachable: bool, exact: bool
) -> Result:
    """Turn a path into inputs and replay them on the engine: only what shows there is reported."""
    inputs, _ = model.concretize(path)
    shown = first_violation(prop, machine, replay(machine, inputs))
    if shown is None:
        return Result(prop, "unknown", explored, detail=NO_REPLAY)
    status = "holds" if reachable else "violated"
    return Result(prop, status, explored, inputs[: shown + 1], shown, exact=exact)


def _check_always_reachable(prop: Property, machine: Machine, budget: int) -> Result:
    graph = Model(machine, 1, prop.watch).explore()
    path, _dead = trapped(graph, prop.cond)
    explored = len(graph.nodes)
    if path is None:
        return Result(prop, "holds", explored)
    model = graph.model
    try:
        exact_graph = Model.exact(machine, prop.watch).explore(budget)
        path, _ = trapped(exact_graph, prop.cond)
        model = exact_graph.model
    except ModelTooLarge:
        pass
    inputs, _ = model.concretize(path or [])
    state = machine.states[path[-1][1][3][0]] if path else machine.states[machine.initial_state]
    return Result(
        prop,
        "violated",
        explored,
        inputs,
        len(inputs) - 1 if inputs else None,
        state=state,
        exact=model.is_exact,
        detail=N_("from state {state} on, no inputs can ever make it happen again", state=state),
    )


#: A result's words shared with tablebot.analysis.prove_product.
NEVER = N_("it can never happen")
NO_REPLAY = N_("the abstract counterexample did not replay; the exact search was too large")

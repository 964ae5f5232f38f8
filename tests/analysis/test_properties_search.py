"""Exhaustive property checking: proofs, shortest counterexamples that replay on the engine, the
found BumberBot bug, and the abstraction checked against the exact model on random tables."""

from __future__ import annotations

import random
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tablebot.analysis.conditions import parse_condition
from tablebot.analysis.model import Model
from tablebot.analysis.properties import Property, load_properties
from tablebot.analysis.prove import check_property, first_violation, monitor_of, search
from tablebot.formats.inputs_csv import TickInput, load_inputs, write_inputs
from tablebot.formats.table_read import load_table
from tablebot.machine import compile_table
from tablebot.replay import replay
from tablebot.robot import MATCHES, Robot
from tablebot.table import Row, Table

pytestmark = [pytest.mark.kernel_free]

if TYPE_CHECKING:
    from tablebot.analysis.prove import Result
    from tablebot.machine import Machine

FIX = Path(__file__).resolve().parents[1] / "fixtures" / "analysis"
EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "bumberbot"


def props_of(table: Path, props: Path | None = None) -> tuple[Machine, dict[str, Property]]:
    machine = compile_table(load_table(table))
    return machine, {p.name: p for p in load_properties(machine, [props or table.with_suffix(".properties.toml")])}


def replayed_violation(machine: Machine, result: Result, tmp_path: Path) -> int | None:
    """Write the counterexample as `tablebot trace` reads it, read it back, replay, run the monitor."""
    path = tmp_path / "cex.csv"
    write_inputs(machine, result.inputs, path)
    return first_violation(result.prop, machine, replay(machine, load_inputs(path, machine)))


def test_bump_counterexample_is_shortest_and_replays(tmp_path: Path) -> None:
    machine, props = props_of(FIX / "bump.csv")
    result = check_property(props["bump_stops"], machine)
    # A at tick 0 (stop, 20 ticks), back off 30 ticks, A exactly when the turn starts, released.
    assert result.status == "violated" and result.exact
    assert len(result.inputs) == 52 and result.at_tick == 51
    assert replayed_violation(machine, result, tmp_path) == 51
    assert result.inputs[50].mask == machine.input_bits["A"] and result.inputs[51].mask == 0


def test_the_fix_makes_it_hold() -> None:
    machine, props = props_of(FIX / "bump_fixed.csv")
    results = {name: check_property(p, machine).status for name, p in props.items()}
    assert results == {"bump_stops": "holds", "backs_off": "holds", "no_spin_in_1": "violated", "returns": "holds"}


def test_too_large_for_the_exact_search_falls_back_to_a_padded_abstract_run(tmp_path: Path) -> None:
    machine, props = props_of(FIX / "bump.csv")
    result = check_property(props["bump_stops"], machine, budget=5)
    assert result.status == "violated" and not result.exact  # not promised shortest, but real:
    assert replayed_violation(machine, result, tmp_path) == result.at_tick == len(result.inputs) - 1


def test_without_a_t_column_the_timer_is_not_tracked() -> None:
    robot = Robot(name="R", inputs=("A",), motors=("M1",), initial_state=1)
    rows = (Row(0, 2, "", 1, frozenset({"A"}), (3,), 500, 2), Row(1, 3, "", 2, frozenset({"A"}), (0,), 900, 1))
    machine = compile_table(Table(robot, ("A",), rows))
    exact = Model.exact(machine).explore()
    assert len(exact.nodes) == 3 and exact.model.is_exact  # start, state 2, back in state 1


def test_never_counterexample(tmp_path: Path) -> None:
    machine, props = props_of(FIX / "bump.csv")
    result = check_property(props["no_spin_in_1"], machine)
    assert result.status == "violated" and len(result.inputs) == 51
    assert replayed_violation(machine, result, tmp_path) == 50


def test_reachable_gives_a_witness_and_impossible_is_a_failure() -> None:
    machine, props = props_of(FIX / "bump.csv")
    result = check_property(props["backs_off"], machine)
    assert result.status == "holds" and len(result.inputs) == 21  # A, then 20 ticks of stopping
    lines = list(replay(machine, result.inputs))
    assert lines[-1]["state"] == 3 and lines[-1]["M1"] < 0
    never = Property("p", "p", "reachable", cond=parse_condition("state == 2 and M1 > 0", machine))
    assert check_property(never, machine).status == "violated"


def test_always_reachable_finds_the_trap() -> None:
    machine = compile_table(load_table(FIX / "trap.csv"))
    prop = Property("back", "back", "always_reachable", cond=parse_condition("state == 1", machine))
    result = check_property(prop, machine)
    assert result.status == "violated" and result.state == 2
    lines = list(replay(machine, result.inputs))
    assert lines[-1]["state"] == 2 and len(lines) == 2  # T wins tick 0; B at tick 1 parks it


def test_counter_witness_uses_pulses() -> None:
    machine = compile_table(load_table(FIX / "counters.csv"))
    prop = Property("w", "w", "reachable", cond=parse_condition("line == 3", machine))
    result = check_property(prop, machine)
    assert result.status == "holds" and [t.pulses for t in result.inputs] == [(0,), (65535,)]
    assert list(replay(machine, result.inputs))[-1]["row"] == 1


def test_bumberbot_found_bug_replays(tmp_path: Path) -> None:
    machine, props = props_of(EXAMPLES / "table.csv", EXAMPLES / "properties.toml")
    result = check_property(props["front_bumper_stops"], machine)
    assert result.status == "violated" and len(result.inputs) == 54
    assert replayed_violation(machine, result, tmp_path) == 53
    last = list(replay(machine, result.inputs))[-2:]
    assert [line["state"] for line in last] == [29, 29]  # turning away, front bumpers ignored
    assert last[-1]["M2"] > 0


def test_fixed_bumberbot_satisfies_every_shipped_property() -> None:
    machine, props = props_of(FIX / "bumberbot_fixed.csv", EXAMPLES / "properties.toml")
    assert {name: check_property(p, machine).status for name, p in props.items()} == dict.fromkeys(props, "holds")


def test_timed_property_is_exact_to_the_tick() -> None:
    machine = compile_table(load_table(EXAMPLES / "table.csv"))

    def pause(ticks: int) -> Property:
        return Property(
            "p",
            "p",
            "when",
            when=parse_condition("state == 20", machine),
            then=parse_condition("state != 20", machine),
            within=ticks,
        )

    assert check_property(pause(50), machine).status == "holds"
    result = check_property(pause(49), machine)
    assert result.status == "violated" and len(result.inputs) == 50 and result.at_tick == 49


def test_within_zero_means_the_same_tick(tmp_path: Path) -> None:
    machine = compile_table(load_table(FIX / "bump.csv"))
    prop = Property(
        "z", "z", "when", when=parse_condition("A", machine), then=parse_condition("M1 == 0", machine), within=0
    )
    result = check_property(prop, machine)
    assert result.status == "violated" and replayed_violation(machine, result, tmp_path) == len(result.inputs) - 1


# --- the abstraction against the exact model, on random tables --------------------------------------

ROBOT = Robot(name="R", inputs=("A", "B"), motors=("M1", "M2"), initial_state=1)
EVENTS = ("T", "A", "B")


@st.composite
def tables(draw: st.DrawFn) -> Table:
    n = draw(st.integers(2, 3))
    rows: list[Row] = []
    for state in range(1, n + 1):
        for _ in range(draw(st.integers(1, 3))):
            events = frozenset(e for e in EVENTS if draw(st.booleans()))
            motors = (draw(st.integers(-2, 2)), draw(st.sampled_from([None, -1, 0, 1])))
            rows.append(
                Row(
                    len(rows),
                    len(rows) + 2,
                    "",
                    state,
                    events,
                    motors,
                    draw(st.integers(0, 6)),
                    draw(st.integers(1, n)),
                )
            )
    robot = replace(ROBOT, match=draw(st.sampled_from(MATCHES)))  # the document's: no event, no row
    return Table(robot, EVENTS, tuple(rows), "<random>")


@settings(max_examples=80, deadline=None)
@given(tables())
def test_the_model_offers_every_row_any_inputs_can_fire(table: Table) -> None:
    """Per state and timer context, the model's input classes reach every outcome some input set gives
    (under the document's rule, an input the state's rows never use still matters on its own)."""
    machine = compile_table(table)
    model = Model(machine)
    every_input_set = range(machine.input_mask + 1)
    for state in range(len(machine.states)):
        for context in (0, machine.timer_bit):
            offered = {row for _, row in model.classes(state, context)}
            assert offered == {
                machine.lookup(state, inputs | context)
                for inputs in every_input_set
                if not inputs & ~machine.input_mask
            }


CONDITIONS = ["A", "state == 1", "state == 2", "M1 > 0", "M2 < 0", "T", "fired", "not A and M1 == 0"]


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(tables(), st.sampled_from(CONDITIONS), st.sampled_from(CONDITIONS), st.integers(0, 4), st.randoms())
def test_abstract_proofs_are_sound_and_counterexamples_real(
    table: Table, when: str, then: str, within: int, rnd: random.Random
) -> None:
    machine = compile_table(table)
    coarse, fine = Model(machine).explore(), Model.exact(machine).explore()
    assert {(n[0], n[3]) for n in coarse.nodes} == {(n[0], n[3]) for n in fine.nodes}  # same situations
    assert coarse.fired_rows() == fine.fired_rows()
    for prop in (
        Property("n", "n", "never", cond=parse_condition(f"{when} and {then}", machine)),
        Property(
            "r", "r", "when", when=parse_condition(when, machine), then=parse_condition(then, machine), within=within
        ),
    ):
        abstract, _ = search(Model(machine, prop.horizon, prop.watch), monitor_of(prop))
        exact, _ = search(Model.exact(machine, prop.watch), monitor_of(prop))
        assert abstract is not None or exact is None  # a proof in the model is a proof
        if prop.kind == "never":  # untimed: the model is exact, not just sound
            assert (abstract is None) == (exact is None)
        result = check_property(prop, machine)
        if result.status == "violated":
            assert first_violation(prop, machine, replay(machine, result.inputs)) == result.at_tick
            assert exact is not None
            assert result.at_tick == len(exact) - 1  # shortest: as long as the exact search's path
        else:
            assert exact is None
            _no_random_run_breaks(machine, prop, rnd)


def _no_random_run_breaks(machine: Machine, prop: Property, rnd: random.Random) -> None:
    for _ in range(5):
        ticks = [TickInput(rnd.getrandbits(2) & machine.input_mask) for _ in range(40)]
        assert first_violation(prop, machine, replay(machine, ticks)) is None

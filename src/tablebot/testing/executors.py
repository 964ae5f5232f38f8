"""The executors of this tablebot, registered in the differential harness (:mod:`tablebot.testing.harness`):
Engine.step, Engine.run (compiled), the simulator, the fleet, the host C engine, the AVR firmware under
simavr, the TXT 4.0 program against its stub (:mod:`tablebot.testing.txt4_executor`), the ROBO Pro program
in its interpreter, and the live serial controllers against their emulators
(:mod:`tablebot.testing.serial_executors`).
"""

from __future__ import annotations

import dataclasses
import random
import shutil
from pathlib import Path
from typing import Any

from tablebot.engine import Engine
from tablebot.machine import Machine, compile_table
from tablebot.replay import record, replay_several
from tablebot.table import Table
from tablebot.testing.harness import CORE, Case, Executor, Run, busy_world, register
from tablebot.testing.robopro_several import fits_robopro_several, robopro_several
from tablebot.testing.serial_executors import SERIAL_EXECUTORS
from tablebot.testing.several_cases import SeveralCase
from tablebot.testing.txt4_executor import TXT4_EXECUTOR


def _engine_step(case: Case, workdir: Path) -> Run:
    engine = Engine(case.machine)
    lines = []
    for tick in case.inputs:
        engine.step(tick.mask, tick.pulses)
        lines.append(record(engine))
    return Run(list(case.inputs), lines)


def _several_step(case: SeveralCase, workdir: Path) -> Run:
    """:class:`tablebot.engine.several.Several`, its tables stepped last to first (any order gives the same
    ticks; the reference steps them first to last)."""
    order = tuple(reversed(range(len(case.tables.machines))))
    return Run(list(case.inputs), list(replay_several(case.tables, case.inputs, order)))


def _host_c_several(case: SeveralCase, workdir: Path) -> Run:
    from tablebot.codegen.host import build_host_several, run_host_several

    exe = build_host_several(case.tables, workdir / "host")
    return Run(list(case.inputs), run_host_several(exe, case.tables, case.inputs))


def _engine_run(case: Case, workdir: Path) -> Run:
    """``Engine.run``, compiled: its columns per tick, and the outputs and counters it leaves after the last."""
    m = case.machine
    engine = Engine(m)
    n = len(m.table.robot.counters)
    pulses = [list(t.pulses) + [0] * (n - len(t.pulses)) for t in case.inputs]
    batch = engine.run([t.mask for t in case.inputs], pulses, jit=True)
    lines: list[dict[str, Any]] = [
        {"tick": i, "event": e, "row": None if r < 0 else r, "state": m.states[s], "timer": t}
        for i, (e, r, s, t) in enumerate(zip(batch.events, batch.rows, batch.states, batch.timers, strict=True))
    ]
    if lines:
        last = record(engine)
        lines[-1].update({k: v for k, v in last.items() if k not in CORE})
    return Run(list(case.inputs), lines)


def _sim_lines(machine: Machine, run: Any) -> Run:
    """A simulated run's (:class:`tablebot.sim.runner.SimRun`) inputs and decisions as trace lines."""
    from tablebot.codegen.host import trace_line

    inputs = run.inputs()
    lines = [
        trace_line(
            machine,
            i,
            int(run.events[i]),
            int(run.rows[i]),
            int(run.states[i]),
            int(run.timers[i]),
            run.outputs[i].tolist(),
            run.counters[i].tolist(),
        )
        for i in range(run.ticks)
    ]
    return Run(inputs, lines)


def _busy_world(seed: int) -> Any:
    """The first of the seed's busy rooms the simulator accepts."""
    from tablebot.diagnostics import TableBotError
    from tablebot.sim.model.world import parse_world
    from tablebot.tomlfile import Source

    rng = random.Random(seed)
    while True:
        try:
            return parse_world(Source.parse("<busy room>", busy_world(rng)))
        except TableBotError:
            continue


def _world_and_layer(case: Case) -> tuple[Any, dict[str, Any] | None]:
    """Where a simulated executor runs the case: its robot's own world and [sim], or a busy random room."""
    from tablebot.sim.model.scene import find_world, robot_layer

    table = case.machine.table
    if case.own_world:
        layer, robot_world = robot_layer(table.robot)
        return find_world(table, None, robot_world), layer
    return _busy_world(case.seed), None


#: Ticks a simulated executor runs (at least).
SIM_TICKS = 1500


def _simulator(case: Case, workdir: Path) -> Run:
    """``tablebot sim``'s path: the run loop handing blocks to ``SimRobot.advance`` (the compiled kernel)."""
    from tablebot.sim.model.scene import prepare
    from tablebot.sim.runner import simulate

    world, layer = _world_and_layer(case)
    scene = prepare(case.machine.table, case.machine, world, layer)
    ticks = max(SIM_TICKS, len(case.inputs))
    return _sim_lines(case.machine, simulate(scene, ticks * scene.tick_s, case.seed))


def _fleet(case: Case, workdir: Path) -> Run:
    """Robot 1 of a fleet of three (``fleet.kernel.run_fleet``), traced."""
    from tablebot.fleet.robots import RobotSpec
    from tablebot.fleet.run import Fleet

    world, layer = _world_and_layer(case)
    specs = [RobotSpec(seed=case.seed + k) for k in range(3)]
    fleet = Fleet(case.machine.table, case.machine, world, specs, layer, traced=[1])
    fleet.run(max(SIM_TICKS, len(case.inputs)), block_ticks=97)
    return _sim_lines(case.machine, fleet.result(1))


def example_case(name: str, seconds: float = 20.0, seed: int = 1) -> Case:
    """A shipped example with the inputs its simulated robot read in ``seconds`` (every other executor replays
    them; the simulated ones run it in its own world)."""
    from tablebot.examples import example_path
    from tablebot.formats.table_read import load_table, resolve_table_path
    from tablebot.sim.model.scene import scene_for
    from tablebot.sim.runner import simulate

    table = load_table(resolve_table_path(example_path(name)))
    machine = compile_table(table)
    run = simulate(scene_for(table, machine), seconds, seed)
    return Case(machine, tuple(run.inputs()), seed, own_world=True)


def _sim_fits(machine: Machine) -> bool:
    return machine.arrays is not None and set(machine.table.robot.motors) >= {"M1", "M2"}


def _host_c(case: Case, workdir: Path) -> Run:
    from tablebot.codegen.host import build_host, run_host

    exe = build_host(case.machine, workdir / "host")
    return Run(list(case.inputs), run_host(exe, case.machine, case.inputs))


def _no_compiler() -> str | None:
    return None if shutil.which("cc") or shutil.which("gcc") else "no C compiler (gcc)"


BOARD = "uno"


def _avr_firmware(case: Case, workdir: Path) -> Run:
    from tablebot.firmware.build import build
    from tablebot.firmware.emulate import emulate

    firmware = build(case.machine, BOARD, workdir / "fw")
    run = emulate(firmware, case.machine, case.inputs, workdir / "run")
    if run.problems:
        raise AssertionError(f"the firmware's stream: {run.problems}")
    return Run(list(case.inputs), run.trace)


def _avr_several(case: SeveralCase, workdir: Path) -> Run:
    from tablebot.firmware.several import build_several, emulate_several

    firmware = build_several(case.tables, BOARD, workdir / "fw")
    return Run(list(case.inputs), emulate_several(firmware, case.tables, case.inputs, workdir / "run"))


def _no_avr() -> str | None:
    from tablebot.diagnostics import TableBotError
    from tablebot.firmware.emulate import build_harness

    if not shutil.which("avr-gcc"):
        return "no avr-gcc (scripts/bootstrap.sh installs gcc-avr)"
    try:
        build_harness()
    except TableBotError as exc:
        return exc.diagnostics[0].message
    return None


def _fits_uno(machine: Machine) -> bool:
    robot = machine.table.robot
    return (
        len(robot.inputs) + len(robot.lamps) <= 8
        and len(robot.motors) <= 2
        and len(robot.counters) <= 2
        and len(machine.states) <= 255
    )


def wired_for_robopro(table: Table) -> Table:
    """A table's robot with a ``[robopro]`` section for a TXT (the controller whose program has counters)."""
    return dataclasses.replace(
        table,
        robot=dataclasses.replace(table.robot, sections={**table.robot.sections, "robopro": {"controller": "txt"}}),
    )


#: Ticks the ROBO Pro interpreter runs of a case at most: it interprets every element (about 1 ms a tick here).
ROBOPRO_TICKS = 1200


def _robopro_program(case: Case, workdir: Path) -> Run:
    """``export --to robopro-program``'s program in the element interpreter (``tablebot.robopro.executor``), on
    the case's first ROBOPRO_TICKS ticks."""
    from tablebot.codegen.host import trace_line
    from tablebot.robopro.executor import run

    m = case.machine
    inputs = list(case.inputs[:ROBOPRO_TICKS])
    decisions = run(wired_for_robopro(m.table), inputs, case.rule)  # type: ignore[arg-type]
    return Run(
        inputs,
        [trace_line(m, i, d.event, d.row, d.state, d.timer, d.outputs, d.counters) for i, d in enumerate(decisions)],
    )


def _fits_robopro(machine: Machine) -> bool:
    from tablebot.robopro.fit import problems
    from tablebot.robot_tables import tables_of

    if tables_of(machine.table.robot):  # a robot of several tables: one process per table
        return fits_robopro_several(machine)
    return not problems(wired_for_robopro(machine.table), "always")


def register_all() -> None:
    """The executors of this tablebot, each once."""
    for executor in (
        Executor(
            "python step",
            _engine_step,
            several=_several_step,
            what="Engine.step: one tick in Python (the path of real robots)",
        ),
        Executor(
            "engine batch",
            _engine_run,
            fits=lambda m: m.arrays is not None,
            what="Engine.run: tick.tick compiled by numba over recorded masks",
        ),
        Executor(
            "simulator",
            _simulator,
            fits=_sim_fits,
            what="tablebot sim: the run loop's blocks through SimRobot.advance (sim.physics.kernel, compiled)",
        ),
        Executor("fleet", _fleet, fits=_sim_fits, what="a robot of a fleet (fleet.kernel.run_fleet, compiled)"),
        Executor(
            "host C",
            _host_c,
            missing=_no_compiler,
            several=_host_c_several,
            what="the generated C engine compiled for this computer (codegen.host)",
        ),
        Executor(
            "AVR firmware",
            _avr_firmware,
            missing=_no_avr,
            fits=_fits_uno,
            several=_avr_several,
            what="the Uno firmware under simavr, its UART trace decoded",
        ),
        TXT4_EXECUTOR,
        # It knows the document's rule too; the reference (Engine.step) does not yet, so only "always" is checked.
        Executor(
            "ROBO Pro program",
            _robopro_program,
            fits=_fits_robopro,
            several=robopro_several,
            what="export --to robopro-program in the ROBO Pro element interpreter",
        ),
        *SERIAL_EXECUTORS,
    ):
        register(executor)


register_all()

"""The ``sweep`` command: thousands of simulated robots over worlds × grid values × seeds, on this
machine's cores or a Dask cluster, one result row per run, pictures, resumable."""

from __future__ import annotations

import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from tablebot.cli.app import app
from tablebot.cli.common import ROBOT_OPT, TABLE_ARG, console, err_console, guarded, out_folder
from tablebot.escape import plain

if TYPE_CHECKING:
    from tablebot.fleet.plan import Plan

WORLD_OPT = typer.Option(None, "--world", help="World TOML; repeat for several worlds (default: the table's arena).")
BACKEND_OPT = typer.Option("auto", "--backend", help="local (this machine's cores) or dask (a cluster); auto: "
                           "dask when a scheduler is named, else local.")
SCHEDULER_OPT = typer.Option(None, "--scheduler", help="Dask scheduler address, tcp://HOST:8786 (or set "
                             "DASK_SCHEDULER_ADDRESS).")
WORKERS_OPT = typer.Option(None, "--workers", min=1, help="Local worker threads (default: one per core).")


@app.command("sweep")
@guarded
def sweep_cmd(
    table: Path = TABLE_ARG,
    world: list[Path] | None = WORLD_OPT,
    robots: int | None = typer.Option(None, "--robots", help="Run N robots: seeds 0..N-1 (or use --seeds)."),
    grid: list[str] | None = typer.Option(None, "--grid", help='KEY=V1,V2,...: battery=1.0,0.6, start=random '
                                          '(or X:Y:HEADING poses), or a simulator parameter such as '
                                          'motor.friction_volts=0.2,0.4. Repeat: every combination runs.'),
    seeds: str | None = typer.Option(None, "--seeds", help="Seeds of each combination: 0..999, 1,5,9 or a mix."),
    seconds: float = typer.Option(60.0, "--seconds", min=0.01, max=3600, help="Simulated time of each run."),
    backend: str = BACKEND_OPT,
    scheduler: str | None = SCHEDULER_OPT,
    workers: int | None = WORKERS_OPT,
    out: Path = typer.Option(Path("out/sweep"), "--out", help="Folder for results.csv, its parts and pictures."),
    plots: bool = typer.Option(True, "--plots/--no-plots", help="Write outcomes.png, starts.png, best.png, worst.png."),
    trace: str | None = typer.Option(None, "--trace", help="Runs to write whole as OUT/trace-RUN.jsonl (the trace "
                                     "tablebot sim writes for that robot): run numbers, e.g. 0,17 or 0..9."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="No progress bar and no summary."),
    robot: Path | None = ROBOT_OPT,
) -> None:
    """Run TABLE on many simulated robots: every world × grid combination × seed, one row per run in
    OUT/results.csv, with pictures. Ctrl-C (or SIGTERM) keeps every finished chunk; the same command again
    resumes."""
    from tablebot.fleet.backends import Runner, choose

    chosen, address = choose(backend, scheduler)
    with Runner(chosen, address, workers) as runner:
        runner.start(imported=False)  # a cluster's workers start up while this process imports and plans
        from tablebot.fileset import current, file_set
        from tablebot.fleet.plan import REPORT_COLUMNS, Store, make_plan, read_results
        from tablebot.interrupts import INTERRUPTS

        if plots:  # before the run (an interrupt never lands in matplotlib's import); not at all without pictures
            from tablebot.fleet.plots import write_all
        runner.imported()  # this process's compiled code is sent to them, or loaded here, while it plans
        plan = make_plan(table, robot, world or [], grid or [], seeds, robots, seconds)
        traced = trace_runs(trace, plan.spec.total)
        out_folder(out, "--out")
        store = Store(out, plan)
        finished = store.open()
        jobs = plan.jobs(skip=finished)
        total, already = plan.spec.total, sum(b - a for a, b in finished)
        if chosen == "local" and jobs:
            from tablebot.fleet.kernel import run_fleet, run_fleet_serial
            from tablebot.jit import say_compiling

            say_compiling("the fleet simulator", run_fleet if len(jobs) == 1 else run_fleet_serial)  # one: threaded
        started = time.perf_counter()
        with Bar("robots", total, quiet, already, plan.spec.ticks) as progress:
            def done(job: Any, summary: Any) -> None:
                store.write_part(job, plan.part_text(job, summary))
                progress.advance(len(summary))
            try:
                runner.run(jobs, done)
            except INTERRUPTS as exc:
                runner.close(failed=True)
                stopped(store, total, exc)
    wall_s = time.perf_counter() - started
    with file_set(out, remove=["results.partial.csv"]):  # results, traces and pictures: all at once
        path, _ = store.merge(complete=True)
        rows = [] if quiet and not plots else \
            read_results(current(path), None if plots else REPORT_COLUMNS)  # pictures read every column
        written = [path, *plan.write_traces(traced, out), *(write_all(plan, rows, out) if plots else [])]
    if not quiet:
        report(plan, rows, written, wall_s, total - already)


def stopped(store: Any, total: int, why: BaseException) -> None:
    """Ctrl-C or SIGTERM: the finished chunks merged into results.partial.csv, then exit 130 (143)."""
    from tablebot.interrupts import Terminated

    path, count = store.merge(complete=False)
    word = "terminated" if isinstance(why, Terminated) else "interrupted"
    err_console.print(f"{word}: {count:,} of {total:,} runs finished, kept in {plain(str(path))}; run the same "
                      "command again to resume", markup=False)
    raise typer.Exit(143 if isinstance(why, Terminated) else 130) from None


def trace_runs(text: str | None, total: int) -> list[int]:
    """The run numbers of ``--trace`` (as --seeds reads numbers), each one of the sweep's runs."""
    from tablebot.diagnostics import TableBotError, fail
    from tablebot.fleet.spec import parse_seeds

    if text is None:
        return []
    try:
        chosen = parse_seeds(text, None, "--trace")
    except TableBotError as exc:  # the words of --seeds, with a hint about run numbers
        raise fail("--trace", exc.diagnostics[0].message, "give run numbers: 0,17 or 0..9") from None
    beyond = [k for k in chosen if k >= total]
    if beyond:
        raise fail("--trace", f"--trace {beyond[0]}: the sweep has runs 0..{total - 1}", "give run numbers it has")
    return list(chosen)


def report(plan: Plan, rows: list[dict[str, str]], written: list[Path], wall_s: float, ran: int) -> None:
    """Success rate per grid value on standard output; the files written on standard error."""
    from tablebot.fleet.plan import groups

    lamps = any(world.lamps for world in plan.worlds)
    for key, values in groups(plan, rows):
        for label, chosen in values:
            name = key if key == "all runs" else f"{key} {label}"
            if lamps:
                line = f"{sum(int(r['reached']) for r in chosen)}/{len(chosen)} reached the lamp"
            else:
                collisions = sum(int(r["collisions"]) for r in chosen) / max(1, len(chosen))
                metres = sum(float(r["distance_m"]) for r in chosen) / max(1, len(chosen))
                line = f"{len(chosen)} runs, {collisions:.1f} collisions and {metres:.2f} m driven a run"
            console.print(plain(f"{name}: {line}"), markup=False)
    if ran:
        rate = ran * plan.spec.ticks / max(wall_s, 1e-9)
        console.print(f"[dim]({ran:,} runs in {wall_s:.1f} s: {rate / 1e6:.2f} M robot-ticks/s)[/dim]")
    for p in written:
        err_console.print(f"wrote {plain(str(p))}", markup=False)


class Bar:
    """A rich progress bar of ``label`` done out of ``total`` and the time left (on a terminal only); given
    the robot-ticks of one item (``ticks``), also the robot-ticks per second."""

    def __init__(self, label: str, total: int, quiet: bool, done: int = 0, ticks: int | None = None) -> None:
        self.label, self.total, self.done, self.ticks = label, total, done, ticks
        self.quiet = quiet or not err_console.is_terminal
        self.started = time.perf_counter()
        self.new = 0

    def __enter__(self) -> Bar:
        if not self.quiet:
            from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

            rate = [TextColumn("{task.fields[rate]}")] if self.ticks else []
            self.bar = Progress(TextColumn(self.label), BarColumn(), MofNCompleteColumn(), *rate,
                                TimeRemainingColumn(), console=err_console, transient=True)
            self.bar.__enter__()
            self.task = self.bar.add_task(self.label, total=self.total, completed=self.done, rate="")
        return self

    def advance(self, count: int) -> None:
        self.new += count
        if self.quiet:
            return
        rate = ""
        if self.ticks:
            per_s = self.new * self.ticks / max(time.perf_counter() - self.started, 1e-9)
            rate = f"{per_s / 1e6:.2f} M robot-ticks/s"
        self.bar.update(self.task, advance=count, rate=rate)

    def __exit__(self, *exc: object) -> None:
        if not self.quiet:
            self.bar.__exit__(None, None, None)

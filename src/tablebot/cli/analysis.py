"""Analysis commands: ``check`` (findings and properties), ``tests`` (golden tests), ``diagram``."""

from __future__ import annotations

import sys
from enum import StrEnum
from pathlib import Path
from typing import TYPE_CHECKING

import typer
from rich.text import Text

from tablebot import registry
from tablebot.cli.app import app
from tablebot.cli.common import (
    FORCE_OPT,
    ROBOT_OPT,
    TABLE_ARG,
    Stages,
    console,
    err_console,
    guarded,
    load,
    open_project,
    out_file,
    out_folder,
)
from tablebot.diagnostics import TableBotError, fail
from tablebot.escape import plain, shell_word, terminal

if TYPE_CHECKING:  # the checker is imported when a command runs: `tablebot --help` stays quick
    from tablebot.analysis.finding import Finding
    from tablebot.analysis.prove import Result
    from tablebot.api.checking import Check

#: The diagram formats (tablebot.analysis.diagram.FORMATS, which a test keeps equal).
FORMATS = ("svg", "png", "dot", "mermaid")

COLOURS = {"error": "red", "warning": "yellow", "info": "cyan"}
#: Findings are printed this many lines at a time (a 100,000-row table can have as many findings).
PRINT_BATCH = 2000


class Format(StrEnum):
    text = "text"
    json = "json"


@app.command("check")
@guarded
def check_cmd(
    table: Path = TABLE_ARG,
    robot: Path | None = ROBOT_OPT,
    properties: list[Path] = typer.Option([], "--properties", "-p", help="Property file(s) (default: "
                                          "NAME.properties.toml or properties.toml beside the table)."),
    target: list[str] = typer.Option([], "--target", help="Export target whose limits to check (repeatable): "
                                     f"{', '.join(registry.check_targets())}."),
    strict: bool = typer.Option(False, "--strict", help="Exit with 1 when there are warnings."),
    verbose: bool = typer.Option(False, "--verbose", "-v", help="List every info finding (overlaps, ignored inputs)."),
    fmt: Format = typer.Option(Format.text, "--format", help="text, or json for machines."),
    cex_dir: Path | None = typer.Option(None, "--counterexamples", help="Folder to write counterexample "
                                        "CSVs into (created if missing); without it, check writes nothing."),
    force: bool = FORCE_OPT,
) -> None:
    """Check a table: rows that never fire, overlaps, unreachable states, loops, properties.

    Exit code 0 when clean, 1 for warnings with --strict, 2 for errors.
    """
    from tablebot.cli.progress import StepBar

    with Stages(total=3) as stages:
        stages.step(f"reading {table}")
        project = open_project(table, robot, properties=properties or None)
        report = project.check(targets=target, progress=StepBar(stages))
    unsaved = _save_counterexamples(report, cex_dir) if cex_dir is not None else None
    if fmt == Format.json:
        sys.stdout.write(report.json_text(strict))
    else:
        _print_report(report, table, verbose, cex_dir is not None)
    if unsaved is not None:  # reported after the report, which a folder problem must not cost the user
        raise unsaved
    raise typer.Exit(report.exit_code(strict))


def _save_counterexamples(report: Check, folder: Path) -> TableBotError | None:
    """Write the counterexample CSVs; returns (not raises) the error of a folder that cannot take them."""
    try:
        report.write_counterexamples(folder)
    except TableBotError as exc:
        return exc
    except OSError as exc:
        return fail(exc.filename or folder, f"counterexamples not written: {exc.strerror or exc}",
                    "give --counterexamples a folder you can write to")
    return None


def _print_report(check: Check, table_arg: Path, verbose: bool, saving: bool) -> None:
    from tablebot.analysis.names import plural

    report = check.report
    machine = report.machine
    table = machine.table
    console.print(f"[bold]{terminal(table.path)}:[/bold] {len(table.rows)} rows, {len(machine.states)} states, "
                  f"robot {terminal(table.robot.name)}; {report.situations} situations explored")
    hidden: dict[str, int] = {}
    shown = []
    for finding in report.findings:
        if finding.severity == "info" and not verbose:
            hidden[finding.code] = hidden.get(finding.code, 0) + 1
            continue
        shown.append(finding)
    _print_findings(table.path, shown)
    if report.results:
        sources = ", ".join(str(p) for p in report.property_files) or table.robot.source
        console.print(f"\n[bold]properties[/bold] ({terminal(sources)}):")
        for result in report.results:
            _print_result(check, result, table_arg, verbose, saving)
    counts = report.counts()
    tail = ""
    if hidden:
        tail = " (" + ", ".join(f"{n} {code}" for code, n in hidden.items()) + "; --verbose lists them)"
    console.print(f"\n{plural(counts['error'], 'error')}, {plural(counts['warning'], 'warning')}, "
                  f"{plural(counts['info'], 'note')}{tail}")


def _print_findings(path: str, findings: list[Finding]) -> None:
    """Findings as styled text (no markup to parse) in batches; plain lines straight to a pipe: a large
    table can have 100,000 findings, and rich's cost is per line and per call."""
    terminal_out = console.is_terminal
    batch: list[Text] = []
    for finding in findings:
        where = f"{finding.path or path}:{finding.lines[0]}" if finding.lines else finding.path or path
        line = [(plain(where) + ":", "bold"), (" ", ""), (finding.severity, COLOURS[finding.severity]),
                (": " + plain(finding.message), "")]
        if finding.hint:
            line += [("\n    ", ""), ("hint:", "dim"), (" " + plain(finding.hint), "")]
        if not terminal_out:
            sys.stdout.write("".join(text for text, _ in line) + "\n")
            continue
        batch.append(Text.assemble(*line))
        if len(batch) == PRINT_BATCH:
            console.print(Text("\n").join(batch))
            batch = []
    if batch:
        console.print(Text("\n").join(batch))
    sys.stdout.flush()


def _print_result(check: Check, result: Result, table_arg: Path, verbose: bool, saving: bool) -> None:
    prop = result.prop
    marks = {"holds": "[green]holds   [/green]", "violated": "[red]VIOLATED[/red]",
             "unknown": "[yellow]unknown [/yellow]"}
    level = f" [dim]({prop.level})[/dim]" if result.status == "violated" and prop.level != "error" else ""
    console.print(f"  {marks[result.status]} [bold]{terminal(prop.name)}[/bold]{level}: {terminal(prop.text)}")
    if verbose or result.failed:
        console.print(f"           [dim]{terminal(prop.claim())}; {result.explored} situations[/dim]")
    if result.detail:
        console.print(f"           {terminal(result.detail)}")
    if prop.note and result.failed:
        console.print(f"           note: {terminal(prop.note)}")
    if not result.inputs:
        return
    path = check.report.counterexamples.get(prop.name)
    kind = "example" if prop.kind == "reachable" else "counterexample"
    shortest = "shortest " if result.exact else ""
    written = (f", written to {terminal(str(path))}" if path else " (not written)" if saving
               else " (--counterexamples DIR saves it)")
    console.print(f"           {shortest}{kind}: {len(result.inputs)} ticks{written}")
    if path:
        command = " ".join(shell_word(str(word)) for word in ("tablebot", "trace", table_arg, "--inputs", path))
        console.print(f"           replay: {terminal(command)}")
    if result.failed or verbose:
        for line in check.story(result):
            console.print(f"             {terminal(line)}")


@app.command("tests")
@guarded
def tests_cmd(
    table: Path = TABLE_ARG,
    out: Path = typer.Option(..., "--out", help="Folder for the golden tests (created if missing)."),
    robot: Path | None = ROBOT_OPT,
    force: bool = FORCE_OPT,
) -> None:
    """Generate golden tests: input CSVs that together fire every row that can fire, each with its
    expected trace (JSON Lines), plus coverage.json."""
    from tablebot.analysis.testgen import generate, write_golden

    _, machine = load(table, robot)
    golden = generate(machine)
    write_golden(golden, out_folder(out, "--out"))
    for seq in golden.sequences:
        console.print(f"wrote {terminal(str(out / seq.inputs_name))} and {terminal(seq.trace_name)} "
                      f"({len(seq.inputs)} ticks, {len(seq.rows)} rows)")
    table_rows = machine.table.rows
    console.print(f"row coverage: {len(golden.covered)} of {len(table_rows)} rows fired "
                  f"({len(golden.fireable)} can fire at all)")
    for index, reason in sorted(golden.reasons.items()):
        console.print(f"  line {table_rows[index].line}: not covered: {terminal(reason)}")
    console.print(f"wrote {terminal(str(out / 'coverage.json'))}")


@app.command("diagram")
@guarded
def diagram_cmd(
    table: Path = TABLE_ARG,
    fmt: str | None = typer.Option(None, "--format", help=f"One of {', '.join(FORMATS)} (default: from "
                                   "--out's suffix, else svg)."),
    out: Path | None = typer.Option(None, "--out", help="File to write (default: standard output)."),
    colour: bool = typer.Option(True, "--colour/--no-colour", help="Colour edges by motion."),
    robot: Path | None = ROBOT_OPT,
    force: bool = FORCE_OPT,
) -> None:
    """Draw the state diagram (the document's Figure 1) from the table."""
    option = "--format"
    suffix = out.suffix.lstrip(".").lower() if out else ""
    named = {"mmd": "mermaid", "gv": "dot"}.get(suffix, suffix)  # the format --out's suffix names, if any
    if fmt is None:
        fmt, option = named or "svg", "--out"
    elif named in FORMATS and named != fmt:  # a .svg file of PNG bytes opens nowhere
        raise fail("--format", f"--format {fmt}, but --out {out} is named as {named}",
                   f"drop --format, or give --out the suffix of {fmt}")
    if fmt not in FORMATS:
        raise fail(option, f"unknown diagram format {fmt!r}", f"use one of {', '.join(FORMATS)} "
                   "(--format, or the suffix of --out: .svg, .png, .dot, .gv, .mermaid, .mmd)")
    from tablebot.analysis.diagram import render
    from tablebot.files import write_bytes

    parsed, _ = load(table, robot)
    data = render(parsed, fmt, colour)
    if out is None:
        sys.stdout.buffer.write(data)
        sys.stdout.flush()
        return
    write_bytes(out_file(out, "--out", make_folder=True), data)
    err_console.print(f"wrote {terminal(str(out))} ({fmt}, {len(data)} bytes)")

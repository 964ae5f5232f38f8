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
from tablebot.diagnostics import HINT_LABEL, TableBotError, fail, severity_word
from tablebot.escape import plain, shell_word, terminal
from tablebot.i18n import N_, _, localise, ngettext

if TYPE_CHECKING:  # the checker is imported when a command runs: `tablebot --help` stays quick
    from tablebot.analysis.finding import Finding
    from tablebot.analysis.prove import Result
    from tablebot.api.checking import Check

#: The diagram formats (tablebot.analysis.diagram.FORMATS, which a test keeps equal).
FORMATS = ("svg", "png", "dot", "mermaid")

COLOURS = {"error": "red", "warning": "yellow", "info": "cyan"}
#: A finding's severity as shown.
FINDING_WORDS = {"error": N_("error"), "warning": N_("warning"), "info": N_("info")}
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
    properties: list[Path] = typer.Option(
        [],
        "--properties",
        "-p",
        help="Property file(s) (default: NAME.properties.toml or properties.toml beside the table).",
    ),
    target: list[str] = typer.Option(
        [], "--target", help=f"Export target whose limits to check (repeatable): {', '.join(registry.check_targets())}."
    ),
    strict: bool = typer.Option(False, "--strict", help="Exit with 1 when there are warnings."),
    verbose: bool = typer.Option(False, "--verbose", "-v", help="List every info finding (overlaps, ignored inputs)."),
    fmt: Format = typer.Option(Format.text, "--format", help="text, or json for machines."),
    cex_dir: Path | None = typer.Option(
        None,
        "--counterexamples",
        help="Folder to write counterexample CSVs into (created if missing); without it, check writes nothing.",
    ),
    force: bool = FORCE_OPT,
) -> None:
    """Check a table: rows that never fire, overlaps, unreachable states, loops, properties.

    Exit code 0 when clean, 1 for warnings with --strict, 2 for errors.
    """
    from tablebot.cli.progress import StepBar

    with Stages(total=3) as stages:
        stages.step(_("reading {path}").format(path=table))
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
        return fail(
            exc.filename or folder,
            N_("counterexamples not written: {reason}", reason=exc.strerror or exc),
            N_("give --counterexamples a folder you can write to"),
        )
    return None


def _print_report(check: Check, table_arg: Path, verbose: bool, saving: bool) -> None:
    report = check.report
    machine = report.machine
    table = machine.table
    console.print(
        f"[bold]{terminal(table.path)}:[/bold] "
        + _("{rows} rows, {states} states, robot {robot}; {situations} situations explored").format(
            rows=len(table.rows),
            states=len(machine.states),
            robot=terminal(table.robot.name),
            situations=report.situations,
        )
    )
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
        heading = _("properties")
        console.print(f"\n[bold]{heading}[/bold] ({terminal(sources)}):")
        for result in report.results:
            _print_result(check, result, table_arg, verbose, saving)
    counts = report.counts()
    tail = ""
    if hidden:
        tail = (
            " ("
            + _("{counts}; --verbose lists them").format(counts=", ".join(f"{n} {code}" for code, n in hidden.items()))
            + ")"
        )
    console.print(
        "\n"
        + ", ".join(
            [
                ngettext("{n} error", "{n} errors", counts["error"]).format(n=counts["error"]),
                ngettext("{n} warning", "{n} warnings", counts["warning"]).format(n=counts["warning"]),
                ngettext("{n} note", "{n} notes", counts["info"]).format(n=counts["info"]),
            ]
        )
        + tail
    )


def _print_findings(path: str, findings: list[Finding]) -> None:
    """Findings as styled text (no markup to parse) in batches; plain lines straight to a pipe: a large
    table can have 100,000 findings, and rich's cost is per line and per call."""
    terminal_out = console.is_terminal
    batch: list[Text] = []
    hint_word = str(localise(HINT_LABEL))
    for finding in findings:
        where = f"{finding.path or path}:{finding.lines[0]}" if finding.lines else finding.path or path
        severity = str(localise(FINDING_WORDS[finding.severity]))
        line = [
            (plain(where) + ":", "bold"),
            (" ", ""),
            (severity, COLOURS[finding.severity]),
            (": " + plain(str(localise(finding.message))), ""),
        ]
        if finding.hint:
            line += [("\n    ", ""), (hint_word + ":", "dim"), (" " + plain(str(localise(finding.hint))), "")]
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
    words = {"holds": _("holds"), "violated": _("VIOLATED"), "unknown": _("unknown")}
    width = max(len(w) for w in words.values())
    colour = {"holds": "green", "violated": "red", "unknown": "yellow"}[result.status]
    mark = f"[{colour}]{words[result.status]:<{width}}[/{colour}]"
    level = (
        f" [dim]({severity_word(prop.level)})[/dim]" if result.status == "violated" and prop.level != "error" else ""
    )
    console.print(f"  {mark} [bold]{terminal(prop.name)}[/bold]{level}: {terminal(prop.text)}")
    if verbose or result.failed:
        console.print(
            f"           [dim]{terminal(str(localise(prop.claim())))}; "
            + _("{n} situations").format(n=result.explored)
            + "[/dim]"
        )
    if result.detail:
        console.print(f"           {terminal(str(localise(result.detail)))}")
    if prop.note and result.failed:
        console.print(f"           {severity_word('note')}: {terminal(prop.note)}")
    if not result.inputs:
        return
    path = check.report.counterexamples.get(prop.name)
    kind = (
        (_("shortest example") if result.exact else _("example"))
        if prop.kind == "reachable"
        else (_("shortest counterexample") if result.exact else _("counterexample"))
    )
    written = (
        _(", written to {path}").format(path=terminal(str(path)))
        if path
        else _(" (not written)")
        if saving
        else _(" (--counterexamples DIR saves it)")
    )
    console.print(
        f"           {kind}: "
        + ngettext("{n} tick", "{n} ticks", len(result.inputs)).format(n=len(result.inputs))
        + written
    )
    if path:
        command = " ".join(shell_word(str(word)) for word in ("tablebot", "trace", table_arg, "--inputs", path))
        console.print("           " + _("replay: {command}").format(command=terminal(command)))
    if result.failed or verbose:
        for line in check.story(result):
            console.print(f"             {terminal(str(localise(line)))}")


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

    machine = load(table, robot)[1]
    golden = generate(machine)
    write_golden(golden, out_folder(out, "--out"))
    for seq in golden.sequences:
        console.print(
            _("wrote {inputs} and {trace} ({ticks} ticks, {rows} rows)").format(
                inputs=terminal(str(out / seq.inputs_name)),
                trace=terminal(seq.trace_name),
                ticks=len(seq.inputs),
                rows=len(seq.rows),
            )
        )
    table_rows = machine.table.rows
    console.print(
        _("row coverage: {covered} of {rows} rows fired ({fireable} can fire at all)").format(
            covered=len(golden.covered), rows=len(table_rows), fireable=len(golden.fireable)
        )
    )
    for index, reason in sorted(golden.reasons.items()):
        console.print(
            "  "
            + _("line {line}: not covered: {reason}").format(
                line=table_rows[index].line, reason=terminal(str(localise(reason)))
            )
        )
    console.print(_("wrote {path}").format(path=terminal(str(out / "coverage.json"))))


@app.command("diagram")
@guarded
def diagram_cmd(
    table: Path = TABLE_ARG,
    fmt: str | None = typer.Option(
        None, "--format", help=f"One of {', '.join(FORMATS)} (default: from --out's suffix, else svg)."
    ),
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
        raise fail(
            "--format",
            N_("--format {fmt}, but --out {out} is named as {named}", fmt=fmt, out=out, named=named),
            N_("drop --format, or give --out the suffix of {fmt}", fmt=fmt),
        )
    if fmt not in FORMATS:
        raise fail(
            option,
            N_("unknown diagram format {fmt!r}", fmt=fmt),
            N_(
                "use one of {formats} (--format, or the suffix of --out: .svg, .png, .dot, .gv, .mermaid, .mmd)",
                formats=", ".join(FORMATS),
            ),
        )
    from tablebot.analysis.diagram import render
    from tablebot.analysis.diagram_tables import render_tables
    from tablebot.files import write_bytes

    project = open_project(table, robot)  # a robot of several tables: one diagram each
    data = render_tables(project.tables, fmt, colour) if project.tables else render(project.table, fmt, colour)
    if out is None:
        sys.stdout.buffer.write(data)
        sys.stdout.flush()
        return
    write_bytes(out_file(out, "--out", make_folder=True), data)
    err_console.print(_("wrote {path} ({fmt}, {size} bytes)").format(path=terminal(str(out)), fmt=fmt, size=len(data)))

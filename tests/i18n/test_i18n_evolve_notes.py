"""evolve's added rows say why they were added in the reader's language (issue 38): the notes the repair and the
mutation give an added row ("guard for P", "a copy of line 5") are made in worker processes, where nobody knows
who reads them, so they travel as messages and the report says them when it writes the table."""

from __future__ import annotations

import pickle
from dataclasses import replace
from pathlib import Path

import numpy as np

from tablebot import i18n
from tablebot.analysis.properties import find_property_files
from tablebot.evolve import space
from tablebot.evolve.operators import Space, vary
from tablebot.evolve.proofs import Prover
from tablebot.evolve.repair import repair
from tablebot.evolve.report import as_table, describe
from tablebot.formats.table_read import load_table
from tablebot.formats.table_write import format_table
from tablebot.table import Table

ROOT = Path(__file__).resolve().parents[2]
BUMBERBOT = ROOT / "examples" / "bumberbot" / "table.csv"


def bumberbot_space() -> tuple[Table, Space]:
    table = load_table(BUMBERBOT)
    made = space.Limits(max_rows=space.default_max_rows(table), timer_max=space.default_timer_max(table))
    return table, Space(table.states, table.robot.motors, replace(made, max_rows=made.max_rows + 10))


def in_german(text_of: object) -> str:
    i18n.use("de")
    try:
        return str(text_of())  # type: ignore[operator]
    finally:
        i18n.use("en")


def test_a_repaired_tables_guard_rows_are_described_in_german() -> None:
    table, sp = bumberbot_space()
    found = repair(space.start(table), table, Prover(find_property_files(BUMBERBOT)), sp, "keep")
    candidate = pickle.loads(pickle.dumps(found.candidate))  # as a worker hands it back
    english = format_table(as_table(candidate, table, Path("repaired.csv")))
    german = in_german(lambda: format_table(as_table(candidate, table, Path("repaired.csv"))))
    assert "keep going (guard for front_bumper_stops)" in english
    assert "weiterfahren (Schutz für front_bumper_stops)" in german and "guard for" not in german


def test_a_copied_row_says_which_line_it_copies_in_german() -> None:
    table, sp = bumberbot_space()
    rng = np.random.default_rng(5)
    start = space.start(table)
    copies = [g for _ in range(200) for g in (vary(start, sp, rng) or ()) if g.origin is None]
    assert copies, "no row was copied in 200 variations"
    gene = pickle.loads(pickle.dumps(copies[0]))
    assert "(added: a copy of line " in describe(gene, table)
    assert "(hinzugefügt: eine Kopie von Zeile " in in_german(lambda: describe(gene, table))


def test_a_resumed_runs_guard_rows_are_described_in_german_too() -> None:
    """A run resumed from its folder reads the repairs an earlier run wrote to repairs.json: the notes come back
    as messages, said in the reader's language (they came back as their English text)."""
    import json

    from tablebot.evolve.run import repaired_from_json, repaired_to_json

    table, sp = bumberbot_space()
    found = repair(space.start(table), table, Prover(find_property_files(BUMBERBOT)), sp, "keep")
    kept = repaired_from_json(json.loads(json.dumps(repaired_to_json(found))))
    german = in_german(lambda: format_table(as_table(kept.candidate, table, Path("repaired.csv"))))
    assert "weiterfahren (Schutz für front_bumper_stops)" in german and "guard for" not in german
    assert kept.candidate == found.candidate  # the genes themselves come back equal

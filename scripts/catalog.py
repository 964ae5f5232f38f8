"""The message catalogs (issue 38): extract the template, update the translations, compile them, check them.

Run from the checkout (Babel is a dev package; the running code reads only the compiled ``.mo`` files):

    .venv/bin/python scripts/catalog.py update   # template from the code, then each language's .po merged with
                                                 # it (new texts untranslated), then compiled to .mo
    .venv/bin/python scripts/catalog.py compile  # .po -> .mo only (after translating)
    .venv/bin/python scripts/catalog.py check    # exit 1 when the template, a .po or a .mo is out of date

The template holds every text marked in the code (``_``, ``N_``, ``ngettext``, ``NP_``: tablebot.i18n) and every
help text of the command line (read from the built commands: docstrings and ``help=``, tablebot.cli.words). Its
locations name files without line numbers, so that a line moved by an unrelated edit leaves it up to date; its
dates are fixed, so that extracting again gives the same bytes. The ``.mo`` files are committed: a wheel built
anywhere (pip, uv, hatchling alone) carries them without a build step of ours, and ``check`` (in make test,
tests/i18n/test_i18n_catalog.py) keeps them equal to what their ``.po`` compiles to.
"""

from __future__ import annotations

import argparse
import io
import re
import sys
from collections.abc import Iterator
from datetime import UTC, datetime
from pathlib import Path

from babel.messages.catalog import Catalog
from babel.messages.extract import extract_from_dir
from babel.messages.mofile import write_mo
from babel.messages.pofile import read_po, write_po

ROOT = Path(__file__).resolve().parents[1]
SOURCE = ROOT / "src" / "tablebot"
LOCALE = SOURCE / "locale"
TEMPLATE = LOCALE / "tablebot.pot"
TRANSLATED = ("de",)
KEYWORDS = {"_": None, "gettext": None, "N_": None, "ngettext": (1, 2), "NP_": (1, 2)}
FIXED_DATE = datetime(2026, 1, 1, tzinfo=UTC)
BRACE_FIELD = re.compile(r"(?<!\{)\{[A-Za-z_][A-Za-z0-9_]*(?:![rsa])?(?::[^{}]*)?\}")
WIDTH = 120


def marked() -> Iterator[tuple[str | tuple[str, str], str]]:
    """(msgid or (singular, plural), file) of every text marked in the code."""
    for filename, _line, message, _comments, _context in extract_from_dir(
        SOURCE, method_map=[("**.py", "python")], keywords=KEYWORDS, comment_tags=()
    ):
        if isinstance(message, tuple):
            singular, plural = message[0], message[1]
            if singular and plural:
                yield (singular, plural), f"src/tablebot/{filename}"
        elif message:
            yield message, f"src/tablebot/{filename}"


def help_texts() -> Iterator[str]:
    """The command line's help texts, as typer builds them (English: no language is chosen here)."""
    import typer.main

    import tablebot.cli  # noqa: F401  (registers every command)
    from tablebot.cli.app import app
    from tablebot.cli.words import help_texts as texts

    yield from texts(typer.main.get_command(app))


def template() -> Catalog:
    catalog = Catalog(
        project="tablebot",
        version="",
        copyright_holder="",
        msgid_bugs_address="",
        creation_date=FIXED_DATE,
        revision_date=FIXED_DATE,
        charset="utf-8",
        fuzzy=False,
    )
    for message, where in marked():
        catalog.add(message, locations=[(where, 0)], flags=_flags(message))
    for text in help_texts():
        catalog.add(text, locations=[("command line help", 0)], flags=_flags(text))
    return catalog


def _flags(message: str | tuple[str, str]) -> tuple[str, ...]:
    text = message if isinstance(message, str) else message[0]
    return ("python-brace-format",) if BRACE_FIELD.search(text) else ()


def po_bytes(catalog: Catalog, header: bool = True) -> bytes:
    out = io.BytesIO()
    write_po(
        out, catalog, width=WIDTH, sort_output=True, include_lineno=False, omit_header=not header, ignore_obsolete=True
    )
    return out.getvalue()


def mo_bytes(catalog: Catalog) -> bytes:
    out = io.BytesIO()
    write_mo(out, catalog, use_fuzzy=False)
    return out.getvalue()


def po_path(language: str) -> Path:
    return LOCALE / language / "LC_MESSAGES" / "tablebot.po"


def read(path: Path, language: str | None = None) -> Catalog:
    with open(path, "rb") as f:
        return read_po(f, locale=language)


def merged(language: str, pot: Catalog) -> Catalog:
    """The language's catalog updated to the template (a text no longer in the code is dropped)."""
    path = po_path(language)
    catalog = (
        read(path, language)
        if path.exists()
        else Catalog(locale=language, project="tablebot", creation_date=FIXED_DATE, fuzzy=False)
    )
    catalog.update(pot, no_fuzzy_matching=True, update_header_comment=False)
    catalog.revision_date = FIXED_DATE
    return catalog


def write(path: Path, data: bytes) -> None:
    """Written beside and renamed into place (tablebot.files' rule, for this tool too)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    temporary = path.with_name(f".{path.name}.tmp")
    temporary.write_bytes(data)
    temporary.replace(path)


def update() -> None:
    pot = template()
    write(TEMPLATE, po_bytes(pot))
    for language in TRANSLATED:
        write(po_path(language), po_bytes(merged(language, pot)))
    compile_all()


def compile_all() -> None:
    for language in TRANSLATED:
        write(po_path(language).with_suffix(".mo"), mo_bytes(read(po_path(language), language)))


def stale() -> list[str]:
    """What is out of date, each with the command that brings it up to date."""
    problems = []
    if not TEMPLATE.exists() or TEMPLATE.read_bytes() != po_bytes(template()):
        problems.append(
            f"{TEMPLATE.relative_to(ROOT)} differs from the texts in the code: run scripts/catalog.py "
            "update, then translate what it adds"
        )
    for language in TRANSLATED:
        po, mo = po_path(language), po_path(language).with_suffix(".mo")
        if not po.exists() or not mo.exists() or mo.read_bytes() != mo_bytes(read(po, language)):
            problems.append(f"{mo.relative_to(ROOT)} is not what {po.name} compiles to: run scripts/catalog.py compile")
    return problems


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("action", choices=("update", "compile", "check"))
    action = parser.parse_args().action
    if action == "update":
        update()
    elif action == "compile":
        compile_all()
    else:
        problems = stale()
        for problem in problems:
            print(problem, file=sys.stderr)
        return 1 if problems else 0
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Every error a user reads is a marked message (issue 38): a ``fail(...)`` or ``Diagnostic(...)`` in
src/tablebot whose message or hint is a plain string literal or f-string would reach a German reader in English
(``OUTDIR: Fehler: --to c needs a folder to write into``). Read from the source's syntax tree, so a new one fails
here before anyone meets it; an N_/_ message (or a variable holding one) passes."""

from __future__ import annotations

import ast
from pathlib import Path

SOURCE = Path(__file__).resolve().parents[2] / "src" / "tablebot"
#: Where each builder takes its message and hint: positions and keywords.
SLOTS = {"fail": ((1, 2), ("message", "hint")), "Diagnostic": ((3, 4), ("message", "hint"))}
#: A collector's methods (diagnostics.Collector, tomlfile.Source, robopro's wiring reader): the place comes first.
COLLECTING = ("error", "key_error")
#: The few that stay as written, with why: a command to type reads the same in every language.
ALLOWED = {
    ("firmware/monitor.py", "pip install pyserial"),
}


def plain(node: ast.expr) -> str | None:
    """The text of a str literal or f-string (or a sum with one), else None; an empty literal (no hint) passes."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return node.value or None
    if isinstance(node, ast.JoinedStr):
        return ast.unparse(node)
    if isinstance(node, ast.BinOp):
        return plain(node.left) or plain(node.right)
    return None


def builder(call: ast.Call) -> str | None:
    func = call.func
    name = func.id if isinstance(func, ast.Name) else func.attr if isinstance(func, ast.Attribute) else None
    return name if name in SLOTS or name in COLLECTING else None


def given_text(call: ast.Call, name: str) -> list[ast.expr]:
    """The arguments of ``call`` that carry a message or a hint."""
    if name in COLLECTING:  # everything after the place (a line, a key, a Where)
        return [*call.args[1:], *(k.value for k in call.keywords)]
    positions, keywords = SLOTS[name]
    return [a for i, a in enumerate(call.args) if i in positions] + [
        k.value for k in call.keywords if k.arg in keywords
    ]


def unmarked(tree: ast.AST) -> list[tuple[int, str]]:
    """(line, text) of every message or hint given to a builder as plain text (given to a collector, a word
    without a space is a key or a name, not a message)."""
    found = []
    for call in (n for n in ast.walk(tree) if isinstance(n, ast.Call)):
        name = builder(call)
        for node in given_text(call, name) if name is not None else []:
            text = plain(node)
            if text is not None and (name in SLOTS or " " in text or isinstance(node, ast.JoinedStr)):
                found.append((call.lineno, text))
    return found


def test_no_error_is_built_from_plain_english() -> None:
    found = []
    for path in sorted(SOURCE.rglob("*.py")):
        where = path.relative_to(SOURCE).as_posix()
        for line, text in unmarked(ast.parse(path.read_text(encoding="utf-8"))):
            if (where, text) not in ALLOWED:
                found.append(f"{where}:{line}: {text}")
    assert not found, "mark these with N_(...) (tablebot.i18n) and translate them:\n" + "\n".join(found)


def test_the_check_sees_each_kind_of_plain_text() -> None:
    """The check itself can fail: literals, f-strings, sums and keywords are seen, messages and variables not."""
    code = (
        'fail("x", "plain")\nfail("x", N_("ok"), f"hint {n}")\nDiagnostic(p, 1, 2, "a" + b)\n'
        'fail("x", message, hint="kw")\nfail("x", N_("ok"), "")\nerrors.Diagnostic(p, 1, 2, N_("ok"), N_("ok"))\n'
        'out.error(3, None, "two words", N_("ok"))\nsrc.key_error(where, N_("ok"), f"{a}")\nr.error("key", N_("ok"))\n'
    )
    assert unmarked(ast.parse(code)) == [
        (1, "plain"),
        (2, "f'hint {n}'"),
        (3, "a"),
        (4, "kw"),
        (7, "two words"),
        (8, "f'{a}'"),
    ]

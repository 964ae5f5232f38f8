"""The harness of test_interrupt_sets.py: a folder's files as a snapshot (inode and digest), the temporary files a
set leaves when cut short, a command run through the CLI with a fault at a given file step
(``TABLEBOT_FAULT``), and the check that each interrupted run left the old set or the new one, never a mix."""

from __future__ import annotations

import hashlib
from collections.abc import Sequence
from pathlib import Path

from typer.testing import CliRunner

from tablebot.cli import app
from tablebot.interrupts import FAULT_ENV

USER_FILE = "my-notes.txt"  # a file of the user's in the output folder: never touched
Snapshot = dict[str, tuple[int, str]]


def snapshot(folder: Path, ignore: Sequence[str] = ()) -> Snapshot:
    """Every file under ``folder`` but ``ignore`` and --force's backups: its inode (a replaced file has a
    new one) and content digest."""
    found = {}
    for path in sorted(folder.rglob("*")):
        if path.is_file() and path.suffix != ".bak" and path.relative_to(folder).parts[0] not in ignore:
            found[path.relative_to(folder).as_posix()] = (
                path.stat().st_ino,
                hashlib.sha256(path.read_bytes()).hexdigest(),
            )
    return found


def leftovers(folder: Path) -> list[str]:
    return [p.name for p in folder.rglob("*") if p.name.startswith(".tablebot-") or p.name.endswith(".tmp")]


def invoke(args: Sequence[object], fault: str | None = None) -> int:
    result = CliRunner().invoke(app, [str(a) for a in args], env={FAULT_ENV: fault} if fault else None)
    assert result.exception is None or isinstance(result.exception, SystemExit), result.exc_info
    return result.exit_code


def check_outcome(folder: Path, before: Snapshot, after: Snapshot, new: Snapshot, loose: Sequence[str]) -> str:
    """'old' when nothing changed, 'new' when the whole set was replaced by one equal to ``new`` (a clean
    run's; files in ``loose`` differ from run to run and are compared by name only)."""
    assert not leftovers(folder), leftovers(folder)
    assert after[USER_FILE] == before[USER_FILE]
    if after == before:
        return "old"
    ours = {name: value for name, value in after.items() if name != USER_FILE}
    assert sorted(ours) == sorted(new), f"a mix: {sorted(ours)} is not the new set {sorted(new)}"
    old_inodes = {inode for inode, _ in before.values()}
    mixed = [name for name, (inode, _) in ours.items() if inode in old_inodes]
    assert not mixed, f"a mix: {mixed} kept from the old set beside new files"
    assert all(ours[n][1] == new[n][1] for n in new if n not in loose), "a new file differs from a clean run's"
    return "new"


def interrupt_everywhere(
    command: Sequence[object],
    folder: Path,
    reference: Path,
    points: Sequence[int] = (),
    loose: Sequence[str] = (),
    ignore: Sequence[str] = (),
) -> list[str]:
    """Run ``command`` (writing into ``folder``) once, and into ``reference`` for the new set; then again
    with the fault at every step (or at ``points``), SIGINT at odd steps and SIGTERM at even ones: each
    run leaves the old set or the new one (``ignore``: files that keep an interrupted run's work, not part
    of the set). Returns the outcomes (ending with 'done')."""
    args = [str(a) for a in command]
    assert invoke([str(reference) if a == str(folder) else a for a in args]) == 0
    new = snapshot(reference, ignore)
    folder.mkdir(parents=True, exist_ok=True)
    (folder / USER_FILE).write_text("mine\n")
    assert invoke(args) == 0
    outcomes = []
    for n in points or range(1, 100):
        name = "INT" if n % 2 else "TERM"
        before = snapshot(folder, ignore)
        code = invoke(args, f"{n}:{name}")
        after = snapshot(folder, ignore)
        if code == 0:
            outcomes.append("done")
            break
        assert code == (130 if name == "INT" else 143)
        outcomes.append(check_outcome(folder, before, after, new, loose))
    return outcomes

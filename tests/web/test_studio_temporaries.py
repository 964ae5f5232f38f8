"""A studio killed mid-save (kill -9) leaves a hidden temporary beside the table; the next start removes it,
and only temporaries of the studio's own naming whose writer is gone (or an hour old), never a user's file.
Real processes: the save is cut by SIGKILL, the sweep is the real studio starting on the folder.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

from core_helpers import EXAMPLE
from tablebot.web.app import Background


@pytest.fixture
def folder(tmp_path: Path) -> Path:
    root = tmp_path / "bot"
    shutil.copytree(EXAMPLE, root)
    return root


KILLED_MID_SAVE = """
import os, sys, time
from pathlib import Path
from tablebot.web import workspace
from tablebot.web.workspace import Kind, Workspace

def stop_before_rename(*args, **kwargs):  # the temporary is written; the rename would come next
    print("written", flush=True)
    time.sleep(60)

folder = Workspace(Path(sys.argv[1]))
opened = folder.read("table.csv", Kind.TABLE, 10**6)
workspace.os.replace = stop_before_rename
folder.save(opened, opened.data.replace(b"Seek", b"Lost"))
"""


def test_a_save_killed_mid_way_leaves_a_temporary_the_next_start_removes(folder: Path) -> None:
    table = (folder / "table.csv").read_bytes()
    child = subprocess.Popen([sys.executable, "-c", KILLED_MID_SAVE, str(folder)], stdout=subprocess.PIPE, text=True)
    assert child.stdout is not None and child.stdout.readline() == "written\n"
    child.kill()  # SIGKILL: nothing of the child's own runs after this
    child.wait()
    left = sorted(p.name for p in folder.iterdir() if p.name.endswith(".tmp"))
    assert left == [f".table.csv.bak.studio-{child.pid}-{left[0][-12:-4]}.tmp"], left
    server = Background(folder)
    server.stop()
    assert not [p for p in folder.iterdir() if p.name.endswith(".tmp")]
    assert (folder / "table.csv").read_bytes() == table


def test_only_the_studios_own_stale_temporaries_are_removed(tmp_path: Path, folder: Path) -> None:
    """Removed: the exact name a save gives, a regular file, its writer gone (or the file an hour old).
    Kept: everything else, however alike."""
    gone = subprocess.run(
        [sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True, check=True
    )
    dead = int(gone.stdout)
    (folder / "sub").mkdir()
    (folder / ".git").mkdir()
    outside = tmp_path / "outside.txt"
    outside.write_text("keep me")
    removed = [
        f".table.csv.studio-{dead}-0123abcd.tmp",
        f"sub/.t.TSV.bak.studio-{dead}-89abcdef.tmp",
        f".table.csv.studio-{os.getpid()}-00000000.tmp",
    ]  # a live writer, but an hour old
    kept = [
        f".table.csv.studio-{os.getpid()}-11111111.tmp",  # a save of this very process may be under way
        ".table.csv.0123abcd.tmp",
        f"table.csv.studio-{dead}-0123abcd.tmp",  # not our name
        f".notes.txt.studio-{dead}-0123abcd.tmp",
        f".table.csv.studio-{dead}-0123ABCD.tmp",
        f".table.csv.studio-{dead}-0123abcd.tmp.keep",
        f".git/.table.csv.studio-{dead}-0123abcd.tmp",
    ]
    for name in removed + kept:
        (folder / name).write_text("x")
    old = time.time() - 2 * 3600
    os.utime(folder / removed[2], (old, old))
    (folder / f".link.csv.studio-{dead}-0123abcd.tmp").symlink_to(outside)  # a link: kept, and its target
    (folder / f".dir.csv.studio-{dead}-0123abcd.tmp").mkdir()
    kept += [f".link.csv.studio-{dead}-0123abcd.tmp", f".dir.csv.studio-{dead}-0123abcd.tmp"]
    server = Background(folder)
    server.stop()
    assert [name for name in removed if (folder / name).exists()] == []
    assert [name for name in kept if not (folder / name).is_symlink() and not (folder / name).exists()] == []
    assert outside.read_text() == "keep me"

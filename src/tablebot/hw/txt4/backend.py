"""``export --to txt4``: a program that runs the table on a TXT 4.0 by itself (then ``tablebot upload``),
registered as an export back-end; it reads the TXT's ``[txt]`` wiring (:mod:`tablebot.hw.txt.backend`)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from tablebot.escape import shell_word
from tablebot.files import out_folder
from tablebot.hw.txt import backend as txt
from tablebot.i18n import N_
from tablebot.registry import ExportBackend, Exported, ExportOptions, register

if TYPE_CHECKING:
    from tablebot.machine import Machine


def export(machine: Machine, out: Path | None, options: ExportOptions) -> Exported:
    from tablebot.hw.txt4.export import export_txt4

    assert out is not None
    workspace = export_txt4(machine)  # a table that does not fit is refused before anything is written
    files = tuple(workspace.write(out_folder(out, "OUTDIR")))
    return Exported(
        files,
        (
            *(N_("wrote {file}", file=str(path)) for path in files),
            N_(
                "upload and start it: tablebot upload {folder} --to txt4://192.168.7.2 (it asks for "
                "the API key the TXT 4.0 shows)",
                folder=shell_word(str(out)),
            ),
        ),
    )


TXT4 = register(
    ExportBackend(
        name="txt4",
        makes="a program that runs the table on a TXT 4.0 by itself",
        help="a program that runs the table on a TXT 4.0 itself (then: tablebot upload)",
        fit=txt.fit,
        export=export,
    )
)

"""`tablebot share`: a link carries a table, its robot file and its world, and gives back exactly those files;
its QR code reads back (by a real decoder) as the link; links that are cut, damaged, of another version or that
carry a broken table are refused in words."""

from __future__ import annotations

import base64
import contextlib
import json
import shutil
import zlib
from pathlib import Path

import pytest
from typer.testing import CliRunner

from tablebot import share
from tablebot.api import open as open_robot
from tablebot.cli import app
from tablebot.diagnostics import TableBotError

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
runner = CliRunner()


def forged(body: object, version: int = share.FORMAT) -> str:
    """A link made as encode() makes one, around any contents."""
    packed = zlib.compress(json.dumps(body).encode("utf-8"))
    return f"{share.STUDIO}#share={version}.{base64.urlsafe_b64encode(packed).decode().rstrip('=')}"


def refusal(link: str) -> str:
    with pytest.raises(TableBotError) as caught:
        share.decode(link, where="--open")
    text = str(caught.value)
    assert text.startswith("--open: error: ") and "Traceback" not in text
    return text


@pytest.mark.parametrize(
    "example", ["bumberbot", "line-follower", "bumberbot-counters", "document/bumberbot-table.tsv"]
)
def test_a_link_gives_back_the_files_byte_for_byte(tmp_path: Path, example: str) -> None:
    link = share.encode(share.collect(EXAMPLES / example))
    folder = tmp_path / "opened"
    table = share.decode(link).write(folder)
    source = EXAMPLES / example
    original = source / "table.csv" if source.is_dir() else source
    assert table.read_bytes() == original.read_bytes()
    opened, first = open_robot(table), open_robot(original)
    assert opened.table.rows == first.table.rows and opened.robot.inputs == first.robot.inputs
    assert opened.default_world().walls == first.default_world().walls  # the world came along (or the empty room)


def test_the_bumberbots_link_is_short_and_names_the_shipped_files(tmp_path: Path) -> None:
    link = share.encode(share.collect(EXAMPLES / "bumberbot"))
    assert link.startswith("http://127.0.0.1:8765/#share=1.") and len(link) < 800  # docs/share.md: 710
    copy = tmp_path / "mine"
    shutil.copytree(EXAMPLES / "bumberbot", copy)
    (copy / "robot.toml").write_text((copy / "robot.toml").read_text() + "# my own note\n")
    longer = share.encode(share.collect(copy))
    assert len(longer) > len(link) + 500  # a changed robot file is carried whole
    assert share.decode(longer).robot == ("robot.toml", (copy / "robot.toml").read_text())


def test_a_robot_files_world_elsewhere_is_carried_as_arena_toml(tmp_path: Path) -> None:
    shared = share.decode(share.encode(share.collect(EXAMPLES / "bumberbot-counters")))
    assert shared.robot is not None and 'world = "arena.toml"' in shared.robot[1]
    assert shared.world == (EXAMPLES / "bumberbot" / "arena.toml").read_text()
    shared.write(tmp_path / "c")
    assert open_robot(tmp_path / "c").robot_world() == tmp_path / "c" / "arena.toml"


def test_the_command_prints_the_link_and_writes_a_qr_code_that_decodes_to_it(tmp_path: Path) -> None:
    import zxingcpp
    from PIL import Image

    png = tmp_path / "bumberbot.png"
    result = runner.invoke(app, ["share", str(EXAMPLES / "bumberbot"), "--qr", str(png)])
    assert result.exit_code == 0, result.output
    link = result.stdout.strip()
    assert link.startswith("http://127.0.0.1:8765/#share=1.") and "\n" not in link
    found = zxingcpp.read_barcodes(Image.open(png))
    assert [code.text for code in found] == [link]
    assert share.decode(found[0].text) == share.collect(EXAMPLES / "bumberbot")


def test_a_cut_link_is_refused_in_words() -> None:
    link = share.encode(share.collect(EXAMPLES / "line-follower"))
    for cut in (len(link) - 1, len(link) - 7, len(link) // 2):
        assert "cut short or damaged" in refusal(link[:cut])
    assert "no '#share='" in refusal("http://127.0.0.1:8765/")
    assert "version is missing" in refusal(link.replace("share=1.", "share="))


def test_a_damaged_link_says_which_character() -> None:
    link = share.encode(share.collect(EXAMPLES / "line-follower"))
    at = len(link) - 20
    text = refusal(link[:at] + " " + link[at + 1 :])
    assert f"(' ' at character {at + 1} of the link)" in text and "chat program" in text


def test_links_of_another_version_are_refused_in_words() -> None:
    body = {"name": "x", "table": ["table.csv", "description,state\n"], "robot": None, "world": None}
    assert "made by a newer tablebot (link format 2" in refusal(forged(body, 2))
    assert "made by an older tablebot (link format 0)" in refusal(forged(body, 0))
    shipped = dict(body, robot=["robot.toml", {"example": "bumberbot/robot.toml", "sha256": "0" * 16}])
    assert "as another version of tablebot ships it" in refusal(forged(shipped))


def test_contents_that_are_not_a_table_or_leave_the_folder_are_refused() -> None:
    assert "not to a table" in refusal(forged(["a list"]))
    assert "not to a table" in refusal(forged({"name": "x", "table": "text"}))
    escape = {"name": "x", "table": ["../../outside.csv", "a"], "robot": None, "world": None}
    assert "names a file '../../outside.csv'" in refusal(forged(escape))
    hidden = {"name": "x", "table": ["table.csv", "a"], "robot": [".bashrc", "a"], "world": None}
    assert "names a file '.bashrc'" in refusal(forged(hidden))
    bomb = base64.urlsafe_b64encode(zlib.compress(b" " * (3 * 2**20), 9)).decode().rstrip("=")
    assert "unpacks to more than 2 MB" in refusal(f"#share=1.{bomb}")


def test_a_link_carrying_a_broken_table_names_the_file_line_and_column() -> None:
    robot = (EXAMPLES / "line-follower" / "robot.toml").read_text()
    body = {
        "name": "broken",
        "table": ["table.csv", "description,state,T,I1,I2,M1,M2,timer,next\ngo,1,1,,,9,6,1s,1\n"],
        "robot": ["robot.toml", robot],
        "world": None,
    }
    shared = share.decode(forged(body))
    with pytest.raises(TableBotError) as caught:
        shared.check("pupils.txt:3")
    assert str(caught.value).startswith("pupils.txt:3: table.csv:2:")  # the motor of 9, in the link's own file


def test_sharing_a_broken_table_is_refused(tmp_path: Path) -> None:
    folder = tmp_path / "mine"
    shutil.copytree(EXAMPLES / "line-follower", folder)
    (folder / "table.csv").write_text("description,state,T,I1,I2,M1,M2,timer,next\ngo,1,1,,,9,6,1s,1\n")
    result = runner.invoke(app, ["share", str(folder)])
    assert result.exit_code == 2 and "table.csv:2:" in result.output and "Traceback" not in result.output


def test_a_qr_code_that_cannot_be_written_is_refused_before_the_link(tmp_path: Path) -> None:
    result = runner.invoke(app, ["share", str(EXAMPLES / "bumberbot"), "--qr", str(tmp_path / "no" / "qr.png")])
    assert result.exit_code == 2 and result.stdout == "" and "the folder of --qr" in result.stderr


def test_any_text_is_a_link_or_refused_in_words() -> None:
    """Whatever is pasted (a damaged link, random bytes after '#share=1.', a forged payload), decode gives the
    files or a TableBotError, never another exception."""
    from hypothesis import given, settings
    from hypothesis import strategies as st

    link = share.encode(share.collect(EXAMPLES / "line-follower"))
    payload = link.split("share=1.", 1)[1]

    @settings(max_examples=300, deadline=None, derandomize=True)
    @given(
        st.one_of(
            st.text(max_size=200).map(lambda t: "#share=1." + t),
            st.binary(max_size=300).map(lambda b: "#share=1." + base64.urlsafe_b64encode(b).decode()),
            st.binary(max_size=300).map(lambda b: "#share=1." + base64.urlsafe_b64encode(zlib.compress(b)).decode()),
            st.integers(0, len(payload)).map(lambda n: link[: len(link) - n]),
            st.tuples(st.integers(0, len(payload) - 1), st.characters()).map(
                lambda c: link[: len(link) - len(payload) + c[0]] + c[1] + link[len(link) - len(payload) + c[0] + 1 :]
            ),
        )
    )
    def pasted(text: str) -> None:
        with contextlib.suppress(TableBotError):  # refused in words is fine; anything else fails the test
            share.decode(text)

    pasted()


def test_a_robot_of_several_tables_is_shared_whole_and_opens_to_the_same_robot(tmp_path: Path) -> None:
    """examples/bumberbot-lights: the link carries the drive table and the lights table (its robot file named as
    shipped), and the folder it opens into runs the same two tables."""
    source = EXAMPLES / "bumberbot-lights"
    shared = share.collect(source / "lights.csv")  # from either table: the robot's tables, the main one first
    assert shared.table[0] == "table.csv" and [name for name, _ in shared.tables] == ["lights.csv"]
    link = share.encode(shared)
    assert len(link) < 1000  # docs/share.md
    table = share.decode(link).write(tmp_path / "opened")
    for name in ("table.csv", "lights.csv", "robot.toml"):
        assert (tmp_path / "opened" / name).read_bytes() == (source / name).read_bytes()
    opened, first = open_robot(table), open_robot(source)
    assert opened.tables is not None and first.tables is not None
    assert [t.rows for t in opened.tables.tables] == [t.rows for t in first.tables.tables]


def test_the_studio_shares_the_tab_it_shows_as_edited_beside_the_others_as_saved(tmp_path: Path) -> None:
    from tablebot.cli.studio import link_maker

    source = EXAMPLES / "bumberbot-lights"
    edited = (source / "lights.csv").read_text().rstrip("\n").rsplit("\n", 1)[0] + "\n"  # the tab's last row deleted
    link, qr = link_maker(source / "lights.csv", edited)
    assert qr.startswith("data:image/svg+xml")
    files = share.decode(link).files()
    assert files["lights.csv"] == edited and files["table.csv"] == (source / "table.csv").read_text()


def test_a_links_other_tables_are_table_files_of_their_own_names() -> None:
    body = {"name": "x", "table": ["table.csv", "a"], "robot": None, "world": None}
    assert "not a table and a robot file" in refusal(forged(dict(body, tables=[["table.csv", "b"]])))
    assert "not a table and a robot file" in refusal(forged(dict(body, tables=[["robot.toml", "b"]])))
    assert "names a file '../x.csv'" in refusal(forged(dict(body, tables=[["../x.csv", "b"]])))
    assert "not to a table" in refusal(forged(dict(body, tables="lights.csv")))


def test_a_table_in_another_folder_cannot_be_carried(tmp_path: Path) -> None:
    folder = tmp_path / "robot"
    shutil.copytree(EXAMPLES / "bumberbot-lights", folder)
    (folder / "parts").mkdir()
    (folder / "lights.csv").rename(folder / "parts" / "lights.csv")
    robot = folder / "robot.toml"
    robot.write_text(robot.read_text().replace('file = "lights.csv"', 'file = "parts/lights.csv"'))
    with pytest.raises(TableBotError) as caught:
        share.collect(folder)
    assert "in another folder (parts/lights.csv)" in str(caught.value) and "Traceback" not in str(caught.value)

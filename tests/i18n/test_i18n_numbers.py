"""Numbers as the reader writes them (issue 38): a decimal comma and a thousands point in German, Python's
point in English and the pseudo-locale; a file's own syntax (a robot file's range, a value it echoes) keeps
the point in every language, because that is what the reader must type."""

from __future__ import annotations

from pathlib import Path

import pytest

from tablebot.diagnostics import TableBotError
from tablebot.i18n import N_, localise, number, use
from tablebot.tomlfile import Source
from tablebot.tomlfile import number as file_number

pytestmark = [pytest.mark.kernel_free]


def test_number_in_each_language() -> None:
    assert number(29.23, ".1f", "de") == "29,2" and number(29.23, ".1f", "en") == "29.2"
    assert number(12000, ",", "de") == "12.000" and number(12000, ",", "en") == "12,000"
    assert number(-0.1234, "+.3f", "de") == "-0,123" and number(0.5, language="de") == "0,5"
    assert number(0.5, ".0%", "de") == "50%" and number(0.5, language="pseudo") == "0.5"


def test_number_follows_the_language_in_use() -> None:
    try:
        use("de")
        assert number(1.5, ".2f") == "1,50"
    finally:
        use("en")
    assert number(1.5, ".2f") == "1.50"


def test_a_message_renders_its_numbers_in_the_readers_language() -> None:
    message = N_("ran {ticks} ticks ({seconds:.2f} s): {reason}", ticks=1500, seconds=1.5, reason="done")
    assert message == "ran 1500 ticks (1.50 s): done"  # its English value (logs, JSON) keeps the point
    assert "(1,50 s)" in message.render("de")
    assert "1.50" in message.render("pseudo")


def test_a_robot_files_range_keeps_its_point_in_german(tmp_path: Path) -> None:
    src = Source.parse(tmp_path / "robot.toml", "[robot]\nwheel = 9.5\n")
    assert file_number(src, ("robot", None, "wheel"), 9.5, 0.01, 0.5) is None
    with pytest.raises(TableBotError) as caught:
        src.raise_if_any()
    said = " ".join(f"{localise(d.message, 'de')} {localise(d.hint, 'de')}" for d in caught.value.diagnostics)
    assert "9.5" in said and "0.01..0.5" in said and "0,01" not in said, said

"""A table's header in German: the names a German spreadsheet gives the columns (issue 38 §2).

A table file is data, so these are read whatever the reader's language (``Zustand`` is ``state`` for an English
reader too), case-insensitive; :func:`header_name` writes a header in a language (``export``/``new --lang de``).
The input, output and counter names (``I3``, ``M1``, ``C1``) are the robot file's, the same in both languages, as
ROBO Pro's German interface names its inputs and motors.
"""

from __future__ import annotations

__all__ = ["FIXED", "GERMAN_FIXED", "GERMAN_SUFFIXES", "header_line", "header_name", "suffix"]

#: The fixed columns, English -> German (ROBO Pro's and the kits' words: Zustand, Folgezustand).
FIXED = {"description": "Beschreibung", "state": "Zustand", "timer": "Timer", "next": "Folgezustand"}
#: The German fixed columns as the reader finds them (lower case, spaces made ``_``) -> the English name.
GERMAN_FIXED = {german.lower(): english for english, german in FIXED.items() if german.lower() != english}
#: An output's fields: ``M1_Richtung``/``M1_Tempo`` (``M1_dir``/``M1_speed``), a counter's ``C1_Laden`` (``C1_load``).
SUFFIXES = {"dir": "Richtung", "speed": "Tempo", "load": "Laden"}
GERMAN_SUFFIXES = {german.lower(): english for english, german in SUFFIXES.items()}


def suffix(word: str) -> str:
    """An output field's suffix in English, lower case (``Richtung`` -> ``dir``; ``Speed`` -> ``speed``)."""
    low = word.lower()
    return GERMAN_SUFFIXES.get(low, low)


def header_name(name: str, language: str) -> str:
    """An English header cell (``state``, ``M1_dir``, ``C1_load``, ``I3``) as written in ``language``."""
    if language != "de":
        return name
    if name in FIXED:
        return FIXED[name]
    base, sep, end = name.rpartition("_")
    if sep and end in SUFFIXES:
        return f"{base}_{SUFFIXES[end]}"
    return name


def header_line(text: str, language: str) -> str:
    """A table's text with its header (its first line) written in ``language``; the rows as they are. The header's
    cells are names (never quoted, never holding the delimiter), split on the delimiter the line uses."""
    if language == "en":
        return text
    first, newline, rest = text.partition("\n")
    delimiter = "\t" if "\t" in first else ";" if ";" in first and "," not in first else ","
    return delimiter.join(header_name(cell, language) for cell in first.split(delimiter)) + newline + rest

"""ROBO Pro, the document's own environment: its three lists (``lists``), lists written into real
programs (``rpp_edit``), and a whole engine program generated from a table (``program``), with an
interpreter of the elements it uses (``interpret``); the vocabulary of real programs it keeps to is
:mod:`tablebot.testing.rpp_vocabulary` (only the tests read it).

Internal to tablebot: its public API is ``tablebot`` and ``tablebot.api`` (docs/api.md, which also names the
modules stable enough to use beside them); anything here may change in any release.
"""

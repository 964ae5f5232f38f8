"""ROBO Pro, the document's own environment: its three lists (``lists``), lists written into real
programs (``rpp_edit``), and a whole engine program generated from a table (``program``), with an
interpreter of the elements it uses (``interpret``) and the vocabulary of real programs it keeps to."""

"""ROBO Pro: the document's three lists and the programs that hold them, as export back-ends."""

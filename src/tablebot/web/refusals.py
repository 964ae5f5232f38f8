"""What the studio's folder (:mod:`tablebot.web.workspace`) says when it turns a file down or finds it changed:
catalog messages (:func:`~tablebot.i18n.N_`), said in each tab's language."""

from __future__ import annotations

import errno

from tablebot.i18n import N_, Message
from tablebot.web.errors import Refused

__all__ = ["OTHER_TAB", "changed", "not_regular", "refusal"]

OTHER_TAB = "saved in another tab"  # how a file changed, when the version there is one this studio wrote


def not_regular(name: str) -> Message:
    return N_("{name} is not a regular file (a folder, pipe or device): the studio skips it", name=name)


def changed(name: str, how: str) -> Message:
    """How a file changed since the tab opened it, in words (``how``: see :class:`ChangedOnDisk`)."""
    if how == OTHER_TAB:
        return N_("{name} was saved in another tab since you opened it", name=name)
    if how == "replaced":
        return N_("{name} was replaced on disk since you opened it", name=name)
    if how == "deleted":
        return N_("{name} was deleted on disk since you opened it", name=name)
    return N_("{name} was changed on disk since you opened it", name=name)


def refusal(exc: OSError, name: str) -> Refused:
    """An OS error on the way to ``name``, in the studio's words."""
    if exc.errno in (errno.ELOOP, errno.ENOTDIR, errno.EMLINK):
        return Refused(
            N_(
                "{name} changed while the studio was opening it (a link appeared on its way): nothing "
                "was read or written; try again",
                name=name,
            )
        )
    if exc.errno == errno.ENXIO:  # a socket
        return Refused(not_regular(name))
    if exc.errno == errno.ENOENT:
        return Refused(N_("there is no file {name} in the folder (moved or deleted?)", name=name))
    if exc.errno in (errno.EACCES, errno.EPERM):
        return Refused(N_("{name} may not be read: check its permissions", name=name))
    return Refused(N_("{name} cannot be opened: {why}", name=name, why=exc.strerror or N_("the system refused")))

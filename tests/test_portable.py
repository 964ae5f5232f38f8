"""Nothing a user runs needs a POSIX-only module or name (issue 34 §1: tablebot's users are on Windows too).

Windows has no ``fcntl``, ``termios``, ``pty``, ``resource``, ``pwd``, ``grp`` (nor ``tty``), no ``os.fork``,
``O_NOFOLLOW``, ``fwalk``..., no SIGKILL or SIGALRM, no ``pthread_sigmask``. Here (Linux) a child Python
starts with a ``sitecustomize`` that makes those modules unimportable for tablebot's code and takes those
names out of ``os`` and ``signal``, and then imports every module of tablebot a user command reaches and runs
the main commands, in folders whose names hold spaces, umlauts and backslashes, on files with Windows line
ends. A library's own POSIX branch (pyserial's serialposix, numpy's ``os.uname``, platformdirs'
``os.getuid``), chosen by its own platform test, is the library's business: only tablebot's imports are
refused, and only the names tablebot's code uses are taken out; a test below fails when tablebot's code
starts using another POSIX-only name, until it is guarded and added here.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

from tablebot.testing.processes import child_env

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src" / "tablebot"
EXAMPLE = ROOT / "examples" / "bumberbot"

POSIX_MODULES = ("fcntl", "termios", "pty", "resource", "pwd", "grp", "tty")
#: POSIX-only names of os and signal that tablebot's code uses (each one guarded), taken out in the child.
OS_NAMES = (
    "fork",
    "forkpty",
    "openpty",
    "ttyname",
    "readv",
    "fwalk",
    "fchmod",
    "setsid",
    "killpg",
    "getpgid",
    "setpgid",
    "mkfifo",
    "O_NOFOLLOW",
    "O_DIRECTORY",
    "O_NOCTTY",
    "O_CLOEXEC",
    "O_NONBLOCK",
)
SIGNAL_NAMES = (
    "SIGKILL",
    "SIGALRM",
    "SIGHUP",
    "SIGQUIT",
    "SIGUSR1",
    "SIGUSR2",
    "setitimer",
    "getitimer",
    "alarm",
    "pause",
    "pthread_sigmask",
    "pthread_kill",
    "sigwait",
    "ITIMER_REAL",
    "SIG_BLOCK",
    "SIG_UNBLOCK",
    "SIG_SETMASK",
)
#: Every POSIX-only name of os and signal (Python's documentation: "Availability: Unix", not Windows) that a
#: module might reach for; tablebot's code may use one only if it is in OS_NAMES / SIGNAL_NAMES above.
POSIX_ONLY = {
    "os": {
        *OS_NAMES,
        "getuid",
        "geteuid",
        "getgid",
        "getegid",
        "getgroups",
        "setuid",
        "setgid",
        "nice",
        "sync",
        "statvfs",
        "fstatvfs",
        "chown",
        "lchown",
        "fchown",
        "chroot",
        "getloadavg",
        "sched_getaffinity",
        "sched_setaffinity",
        "pipe2",
        "writev",
        "preadv",
        "pwritev",
        "posix_spawn",
        "wait3",
        "wait4",
        "WNOHANG",
        "register_at_fork",
        "sysconf",
        "confstr",
        "pathconf",
        "getpgrp",
        "tcgetpgrp",
        "ctermid",
        "O_SYNC",
        "O_DSYNC",
        "O_ASYNC",
        "O_NDELAY",
        "O_PATH",
        "fchdir",
        "mknod",
        "major",
        "minor",
        "getsid",
        "setpgrp",
    },
    "signal": {
        *SIGNAL_NAMES,
        "SIGCHLD",
        "SIGPIPE",
        "SIGCONT",
        "SIGSTOP",
        "SIGTSTP",
        "SIGTTIN",
        "SIGTTOU",
        "SIGWINCH",
        "SIGIO",
        "SIGPROF",
        "SIGVTALRM",
        "SIGXCPU",
        "sigpending",
        "sigtimedwait",
        "sigwaitinfo",
        "siginterrupt",
        "ITIMER_VIRTUAL",
        "ITIMER_PROF",
        "pidfd_send_signal",
    },
}

HOOK = f"""
import builtins, os, signal, sys
BLOCKED = {set(POSIX_MODULES)!r}
_import = builtins.__import__


def _as_on_windows(name, globals=None, locals=None, fromlist=(), level=0):
    # tablebot's own `import fcntl` raises ImportError, as on Windows; a library's POSIX branch (pyserial's
    # serialposix, chosen by its own platform test) is the library's business
    importer = (globals or {{}}).get("__name__") or ""
    if level == 0 and name.split(".")[0] in BLOCKED and importer.split(".")[0] == "tablebot":
        raise ModuleNotFoundError(f"No module named {{name!r}} (as on Windows)", name=name)
    return _import(name, globals, locals, fromlist, level)


builtins.__import__ = _as_on_windows
for module, names in ((os, {OS_NAMES!r}), (signal, {SIGNAL_NAMES!r})):
    for name in names:
        if hasattr(module, name):
            delattr(module, name)
os.supports_dir_fd = set()  # no function takes dir_fd (openat), as on Windows, where passing one raises


def _no_dir_fd(function):
    def called(*args, dir_fd=None, src_dir_fd=None, dst_dir_fd=None, **kwargs):
        if (dir_fd, src_dir_fd, dst_dir_fd) != (None, None, None):
            raise NotImplementedError(f"{{function.__name__}}: dir_fd unavailable on this platform")
        return function(*args, **kwargs)
    return called


for name in ("open", "stat", "unlink", "remove", "rename", "replace", "mkdir", "rmdir"):
    setattr(os, name, _no_dir_fd(getattr(os, name)))

import multiprocessing
import multiprocessing.context as _contexts

# processes start by spawn, as on Windows, which has no fork server (nor fork: see os.fork above)
_contexts._concrete_contexts.pop("forkserver", None)
multiprocessing.set_start_method("spawn", force=True)
"""

#: Modules no user command imports: test helpers (a pseudo-terminal standing in for a serial device).
NOT_FOR_USERS = ("tablebot.testing",)


@pytest.fixture(scope="module")
def windowsish(tmp_path_factory: pytest.TempPathFactory) -> dict[str, str]:
    """The environment of a child Python with the POSIX-only modules and names gone."""
    hook = tmp_path_factory.mktemp("hook")
    (hook / "sitecustomize.py").write_text(HOOK, encoding="utf-8")
    return child_env(PYTHONPATH=str(hook), COLUMNS="200")


def tablebot(env: dict[str, str], cwd: Path, *args: str) -> subprocess.CompletedProcess[str]:
    done = subprocess.run(
        [sys.executable, "-m", "tablebot", *args], cwd=cwd, env=env, capture_output=True, text=True, timeout=300
    )
    assert done.returncode in (0, 1), f"tablebot {' '.join(args)} failed ({done.returncode}):\n{done.stderr[-3000:]}"
    assert "Traceback" not in done.stderr and "internal error" not in done.stderr, done.stderr[-3000:]
    return done


def test_the_hook_takes_the_posix_modules_and_names_away(windowsish: dict[str, str]) -> None:
    probe = (
        "import os, signal\n"
        f"for name in {POSIX_MODULES!r}:\n"
        "    try:\n        exec('import ' + name, {'__name__': 'tablebot.probe'})\n"
        "    except ImportError:\n        pass\n"
        "    else:\n        raise SystemExit('imported ' + name)\n"
        "print(hasattr(os, 'fork'), hasattr(os, 'O_NOFOLLOW'), hasattr(signal, 'SIGKILL'),\n"
        "      hasattr(signal, 'SIGINT'))"
    )
    done = subprocess.run([sys.executable, "-c", probe], env=windowsish, capture_output=True, text=True, check=True)
    assert done.stdout.split() == ["False", "False", "False", "True"]


def test_every_module_a_user_command_reaches_imports_without_them(windowsish: dict[str, str]) -> None:
    program = (
        "import importlib, pkgutil, tablebot\n"
        f"skip = {NOT_FOR_USERS!r}\n"
        "names = [m.name for m in pkgutil.walk_packages(tablebot.__path__, 'tablebot.')]\n"
        "for name in names:\n"
        "    if not name.startswith(skip) and not name.endswith('__main__'):  # that one runs the CLI\n"
        "        importlib.import_module(name)\n"
        "print(len(names))"
    )
    done = subprocess.run([sys.executable, "-c", program], env=windowsish, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr[-3000:]
    assert int(done.stdout) > 100  # the whole package was walked


def test_tablebot_uses_no_posix_only_name_that_the_hook_leaves_in_place() -> None:
    """A new use of a POSIX-only name of os or signal must be listed above (so that the commands below run
    without it) or, where a library needs the name and the hook cannot take it away (os.getuid), be guarded
    in its file: ``hasattr(os, "getuid")``."""
    listed = {"os": set(OS_NAMES), "signal": set(SIGNAL_NAMES)}
    unguarded = []
    for path in sorted(SRC.rglob("*.py")):
        if path.is_relative_to(SRC / "testing"):
            continue
        text = path.read_text(encoding="utf-8")
        for module in ("os", "signal"):
            for name in sorted(set(re.findall(rf"\b{module}\.([A-Za-z_]+)\b", text))):
                guarded = re.search(rf"(hasattr|getattr)\({module}, \"{name}\"", text)
                if name in POSIX_ONLY[module] and name not in listed[module] and not guarded:
                    unguarded.append(f"{path.relative_to(ROOT)}: {module}.{name}")
    assert not unguarded, f"POSIX-only, not on Windows: {unguarded}; guard with hasattr({{module}}, NAME)"


def crlf(path: Path) -> None:
    path.write_bytes(path.read_bytes().replace(b"\r\n", b"\n").replace(b"\n", b"\r\n"))


def test_the_main_commands_run_without_them_in_awkward_folders(windowsish: dict[str, str], tmp_path: Path) -> None:
    home = tmp_path / "Schüler Arbeit\\Gruppe 1"  # a space, an umlaut and a backslash (a plain character here)
    home.mkdir(parents=True)
    tablebot(windowsish, home, "new", "mein Roboter")
    robot = home / "mein Roboter"
    for name in ("table.csv", "robot.toml"):
        crlf(robot / name)  # as Notepad or Excel on Windows save them
    assert b"\r\n" in (robot / "table.csv").read_bytes()
    checked = tablebot(windowsish, home, "check", "mein Roboter")
    assert "error" in checked.stdout and "0 errors" in checked.stdout
    tablebot(windowsish, home, "sim", "mein Roboter", "--seconds", "5", "--out", "Läufe\\erster")
    run = home / "Läufe\\erster"
    assert {"trace.jsonl", "trajectory.png", "timeline.png"} <= {p.name for p in run.iterdir()}
    assert not [p.name for p in run.iterdir() if p.name.startswith(".tablebot-")]  # the staging folder went
    tablebot(windowsish, home, "export", "mein Roboter", "C Quelle", "--to", "c")
    assert list((home / "C Quelle").glob("*.c"))
    ran = tablebot(windowsish, home, "run", str(EXAMPLE), "--on", "sim", "--seconds", "0.5")
    assert "ran 50 ticks" in ran.stdout + ran.stderr
    tablebot(windowsish, home, "sim", str(EXAMPLE), "--seconds", "5", "--out", "Läufe\\erster")  # replaces the set
    assert (run / "trace.jsonl").read_text(encoding="utf-8").count("\n") > 400


def test_sweep_and_evolve_with_worker_processes_started_as_on_windows(
    windowsish: dict[str, str], tmp_path: Path
) -> None:
    """evolve's provers are processes: from a fork server on POSIX, spawned on Windows (which has none)."""
    home = tmp_path / "Schüler Arbeit"
    home.mkdir()
    tablebot(windowsish, home, "sweep", str(EXAMPLE), "--robots", "8", "--seconds", "3", "--out", "Flotte")
    assert (home / "Flotte" / "results.csv").exists()
    tablebot(
        windowsish,
        home,
        "evolve",
        str(EXAMPLE),
        "--out",
        "Evolution",
        "--budget",
        "3",
        "--batch",
        "2",
        "--seeds",
        "0..1",
        "--check-seeds",
        "10..11",
        "--seconds",
        "2",
        "--workers",
        "2",
        "-q",
    )
    assert (home / "Evolution").is_dir()


#: The studio's file access where no function takes dir_fd: read, list, save with a backup, a save that lost
#: to an edit on disk, and a link on the way refused.
WORKSPACE = """
import os, sys
from pathlib import Path
from tablebot.web.errors import Refused
from tablebot.web.workspace import AT_FOLDER, ChangedOnDisk, Kind, Workspace
assert not AT_FOLDER
root = Path(sys.argv[1])
ws = Workspace(root)
assert ws.listing()["tables"] == ["Gruppe ä/table.csv"], ws.listing()
opened = ws.read("Gruppe ä/table.csv", Kind.TABLE, 1 << 20)
saved = ws.save(opened, opened.data.replace(b"895", b"900"))
assert (root / "Gruppe ä/table.csv").read_bytes() == saved.file.data and b"900" in saved.file.data
assert (root / "Gruppe ä/table.csv.bak").read_bytes() == opened.data
(root / "Gruppe ä/table.csv").write_bytes(opened.data)  # another program's edit
try:
    ws.save(saved.file, saved.file.data + b"#\\r\\n")
except ChangedOnDisk as exc:
    print("conflict:", exc)
(root / "link").symlink_to(root / "Gruppe ä", target_is_directory=True)
try:
    ws.save(saved.file.__class__("link/table.csv", saved.file.identity, saved.file.data, saved.file.mode), b"x")
except Refused as exc:
    print("refused:", exc)
print("left:", sorted(p.name for p in (root / "Gruppe ä").iterdir()))
"""


def test_the_studios_files_are_read_and_saved_without_dir_fd(windowsish: dict[str, str], tmp_path: Path) -> None:
    folder = tmp_path / "Klasse 7\\b" / "Gruppe ä"
    folder.mkdir(parents=True)
    for name in ("table.csv", "robot.toml"):
        (folder / name).write_bytes((EXAMPLE / name).read_bytes())
    done = subprocess.run(
        [sys.executable, "-c", WORKSPACE, str(folder.parent)],
        env=windowsish,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    said = done.stdout.splitlines()
    assert said[0].startswith("conflict: Gruppe ä/table.csv was changed on disk since you opened it"), said
    assert said[1].startswith("refused: link/table.csv now leads to another file"), said
    assert said[2] == "left: ['robot.toml', 'table.csv', 'table.csv.bak']", said  # no temporary left behind

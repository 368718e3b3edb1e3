"""Output files: one policy for every command that writes one (no I/O libraries here).

- An existing path is refused unless the caller said ``overwrite`` (``exists_error``: the
  one "already exists", an ``OutputError`` from every writer, result files included).
- A path that is a command's own input is refused even with ``overwrite``: every file the
  command reads (the scene, its records and record listings, the result being plotted,
  a hazard or measured CSV), compared by the file's identity (device and inode: a
  symbolic or hard link, ``..`` or another spelling of an input is that input;
  ``is_input``). A scene lists what it read (``Scene.inputs``).
- Only regular files are written: a directory, a device (``/dev/null``, ``/dev/full``), a
  FIFO or a socket is refused even with ``overwrite``.
- The directory must exist and be writable, and the name must fit the file system.
- Files appear atomically: they are written under a temporary name unique to the process
  (``partial_prefix``: the writer's pid, in the target's directory) and published when
  complete (``publish``, the one rename of every output, result files included), so an
  output is either complete or absent, and two processes writing the same path never
  share a temporary file. A new file gets the mode the umask gives (``new_file_mode``).
- One publish rule: a file the command was not told to replace is never replaced. Without
  ``overwrite`` the temporary file is hard-linked to the target, which fails if a file
  appeared there while the command computed; with ``overwrite`` only the file
  ``check_output`` saw is replaced. The temporary files of a killed command are removed by
  the next command writing the same path (``clean_stale_partials``).

Every refusal is an ``OutputError`` (a ``RocksweepError``) with one line naming the path
and the reason.
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import os
import re
import stat
import tempfile
import time
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path

from rocksweep.errors import OutputError, flag


def os_reason(err: OSError) -> str:
    if err.errno == errno.ENOSPC:
        return "no space left on the device"
    if err.errno == errno.ENAMETOOLONG:
        return "file name too long"
    if err.errno == errno.ELOOP:
        return "a loop of symbolic links"
    if err.errno in (errno.EACCES, errno.EPERM, errno.EROFS):
        return "permission denied (read-only location?)"
    return err.strerror or type(err).__name__


def _identity(path: str | Path) -> tuple[int, int] | None:
    """(device, inode) of the file ``path`` names, links followed; None when there is
    none (missing, a dangling link or a loop of links, a name no file can have)."""
    try:
        st = os.stat(path)
    except (OSError, ValueError):
        return None
    return st.st_dev, st.st_ino


def is_input(path: str | Path, inputs: Iterable[str | Path | None]) -> bool:
    """Whether ``path`` is one of the files ``inputs`` (None entries skipped): the same
    file, whatever the spelling (a symbolic or hard link, ``..``, relative or absolute),
    by device and inode."""
    own = _identity(path)
    if own is None:
        return False
    return any(inp is not None and _identity(inp) == own for inp in inputs)


def shown(path: str | Path) -> str:
    """A path as error messages show it: one readable line (control characters such as a
    newline escaped as in Python, ``\\n``; long names shortened)."""
    text = str(path)
    if any(ord(c) < 32 or ord(c) == 127 for c in text):
        text = text.encode("unicode_escape", "backslashreplace").decode("ascii")
    return text if len(text) <= 120 else f"{text[:60]}...{text[-40:]}"


def check_path_text(path: object, name: str = "output") -> Path:
    """``path`` as a Path: a TypeError unless it is a ``str`` or ``os.PathLike``, an
    OutputError for an empty path or one holding a NUL byte (no file can have it)."""
    if isinstance(path, bytes) or not isinstance(path, str | os.PathLike):
        raise TypeError(f"{name} = {path!r}: must be a path (str or pathlib.Path)")
    text = os.fspath(path)
    if isinstance(text, bytes) or not text:
        raise OutputError(f"{name} = {path!r}: give a file name")
    if "\0" in text:
        raise OutputError(f"{shown(text)}: a NUL byte in a file name; no file can have it")
    return Path(text)


def input_problem(path: str | Path) -> str | None:
    """Why ``path`` cannot be read as an input file (a scene, a record, a result): None
    for a regular file; else the reason, without the path ("no such file", "a FIFO..."):
    reading a FIFO with no writer, a character device or a directory would block or fail
    (checked with ``stat``, which never blocks)."""
    try:
        st = os.stat(path)
    except FileNotFoundError:
        return "a symbolic link to a missing file" if os.path.lexists(path) else \
            "no such file"
    except (OSError, ValueError) as err:  # ValueError: a NUL byte in the name
        return os_reason(err) if isinstance(err, OSError) else "not a valid file name"
    if stat.S_ISDIR(st.st_mode):
        return "is a directory, not a file"
    if not stat.S_ISREG(st.st_mode):
        kind = ("a FIFO (named pipe)" if stat.S_ISFIFO(st.st_mode) else
                "a socket" if stat.S_ISSOCK(st.st_mode) else "a device")
        return f"is {kind}, not a regular file; inputs are read from regular files only"
    return None


def check_distinct(paths: dict[str, str | Path | None]) -> None:
    """Refuse (OutputError) one file given for two outputs of a command, whatever the
    spellings (``a.png`` and ``$PWD/a.png``, a symbolic link): compared by resolved path,
    before anything is written. paths: option name -> path (None: not given)."""
    seen: dict[str, str] = {}
    for option, p in paths.items():
        if p is None:
            continue
        try:
            key = os.path.realpath(p)
        except (OSError, ValueError):
            continue
        if key in seen:
            raise OutputError(f"{shown(p)}: given to both {seen[key]} and {option}; "
                              "give each output its own file")
        seen[key] = option


def exists_error(path: str | Path, resumable: bool = False) -> OutputError:
    """The one refusal of an existing output, from every writer: an ``OutputError`` (an
    ``OSError``, as ``FileExistsError``; the output path's problem, like the others of this
    module), saying how to go on: ``overwrite``, and for a result file ``resume``."""
    if resumable:
        return OutputError("{path}: already exists; use {resume} to finish it or {overwrite} "
                           "to replace it", path=shown(path), resume=flag("resume"),
                           overwrite=flag("overwrite"))
    return OutputError("{path}: already exists; use {overwrite} to replace it",
                       path=shown(path), overwrite=flag("overwrite"))


def check_output(path: str | Path, *, overwrite: bool = False,
                 inputs: Iterable[str | Path] = (), suffixes: Iterable[str] = ()) -> Path:
    """Check that ``path`` may be written; return it as a Path, or raise OutputError.

    inputs: the command's input files (never written over); suffixes: allowed file
    suffixes (e.g. (".png", ".pdf", ".svg")), empty for any.
    """
    path = check_path_text(path)
    suffixes = tuple(suffixes)
    if suffixes and path.suffix.lower() not in suffixes:
        raise OutputError(f"{shown(path)}: unsupported file type {path.suffix or '(none)'!r}; "
                          f"use one of {', '.join(suffixes)}")
    try:
        st = os.stat(path)
    except FileNotFoundError:
        st = None
    except OSError as err:
        raise OutputError(f"{shown(path)}: cannot be written ({os_reason(err)})") from None
    if st is not None:
        if stat.S_ISDIR(st.st_mode):
            raise OutputError(f"{shown(path)}: is a directory; give a file name")
        if not stat.S_ISREG(st.st_mode):
            raise OutputError(f"{shown(path)}: not a regular file (a device, FIFO or socket); "
                              "outputs are written to regular files only")
        if is_input(path, inputs):
            raise OutputError(f"{shown(path)}: is this command's input; choose another "
                              "output path")
        if not overwrite:
            raise exists_error(path)
    parent = path.parent if str(path.parent) else Path(".")
    if not parent.is_dir():
        raise OutputError(f"{shown(path)}: directory {shown(parent)} does not exist")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise OutputError(f"{shown(path)}: directory {shown(parent)} is not writable")
    try:
        name_max = os.pathconf(parent, "PC_NAME_MAX")
    except (OSError, ValueError):
        name_max = 255
    # the temporary name adds a few characters; refuse what cannot be made at all
    if len(os.fsencode(path.name)) > name_max:
        raise OutputError(f"{shown(path)}: file name too long "
                          f"({len(os.fsencode(path.name))} bytes, at most {name_max})")
    _CHECKED[os.path.abspath(path)] = None if st is None else (st.st_dev, st.st_ino,
                                                               st.st_ctime_ns)
    return path


def new_file_mode() -> int:
    """The mode a new file gets under this process's umask (mkstemp makes files 0600):
    read from /proc (threads may be running: ``os.umask`` would set it to read it)."""
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return 0o666 & ~int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    mask = os.umask(0o022)  # no /proc: read it the only other way, then put it back
    os.umask(mask)
    return 0o666 & ~mask


def publish(tmp: Path, path: Path, *, old: tuple[int, int, int] | None = None,
            old_fd: int | None = None) -> None:
    """Rename the finished temporary file ``tmp`` to ``path`` with a new file's mode: the
    one rename of every output, and its one rule: never replace a file the command was not
    told to replace. Without ``old``/``old_fd``, ``path`` must still be absent (``tmp`` is
    hard-linked to it, which fails if another process made it since it was checked);
    with ``old`` (``file_seen`` of the file the command was told to overwrite) or
    ``old_fd`` (that file held open), that file is replaced only if it is still the one at
    ``path`` (and if it vanished meanwhile, ``path`` is made as a new file). OutputError
    when another process got there first; ``tmp`` is then left for the caller to remove."""
    os.chmod(tmp, new_file_mode())
    if old is not None or old_fd is not None:
        if old_fd is not None:  # held open: its inode cannot be reused
            try:
                now = os.stat(path)
                same = os.path.samestat(os.fstat(old_fd), now)
            except OSError:
                now, same = None, False
            there = now is not None or os.path.lexists(path)
        else:
            seen = file_seen(path)
            same, there = seen == old, seen is not None
        if same:
            os.replace(tmp, path)
            return
        if there:
            raise OutputError(f"{shown(path)}: replaced by another process meanwhile; not "
                              "overwritten")
    try:
        os.link(tmp, path)
    except FileExistsError:
        raise OutputError(f"{shown(path)}: made by another process meanwhile (the same "
                          "command started at the same time?); not overwritten") from None
    except OSError as err:
        if err.errno not in (errno.EPERM, errno.ENOTSUP, errno.EOPNOTSUPP, errno.EXDEV,
                             errno.EMLINK):
            raise
        if os.path.lexists(path):  # no hard links here: check, then rename
            raise OutputError(f"{shown(path)}: made by another process meanwhile; not "
                              "overwritten") from None
        os.replace(tmp, path)
        return
    with contextlib.suppress(OSError):
        os.unlink(tmp)


def file_seen(path: str | Path) -> tuple[int, int, int] | None:
    """What is at ``path``: (device, inode, status-change time [ns]) of the file (links
    followed; the time tells a new file from an old one that reused the inode), (-1, -1,
    -1) for a dangling link, None when nothing is."""
    try:
        st = os.stat(path)
    except (OSError, ValueError):
        return (-1, -1, -1) if os.path.lexists(path) else None
    return st.st_dev, st.st_ino, st.st_ctime_ns


# What ``check_output`` saw at each output path (absolute path -> ``file_seen``, None:
# absent): the file ``atomic_path(..., overwrite=True)`` may replace is that one, not one
# that appeared while the command computed.
_CHECKED: dict[str, tuple[int, int, int] | None] = {}

_PARTIAL = re.compile(r"\.(?:(\d+)-)?[a-z0-9_]{8}\.partial(?:\.[A-Za-z0-9]{1,8})?")
STALE_AGE = 60.0  # [s] a partial file without a writer's pid is stale when this old


def partial_prefix(path: Path) -> str:
    """The prefix of the temporary names an output at ``path`` is made under: the
    writer's pid is part of the name (``.out.h5.1234-abcd1234.partial``, a suffix such as
    ``.h5`` or ``.png`` may follow), so that a later run can tell a killed writer's file."""
    return f".{path.name[:40]}.{os.getpid()}-"


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # exists, another user's
        return True
    return True


def clean_stale_partials(path: Path) -> list[tuple[str, int]]:
    """Remove the temporary files of earlier attempts to make ``path`` that no live writer
    owns (a command killed while writing leaves one; a sweep's has the reserved size): its
    writer's process is gone (or, for a name without a pid, it is older than STALE_AGE)
    and no process holds its lock (HDF5's writer lock, flock). Returns (name, bytes) of
    each file removed."""
    path = Path(path)
    parent = path.parent if str(path.parent) else Path(".")
    # files of older versions were named after the stem (``.risk.abcd1234.partial.h5``)
    heads = {f".{path.name[:40]}", f".{path.stem[:40]}"}
    removed = []
    try:
        names = [n for n in os.listdir(parent) if ".partial" in n
                 and any(n.startswith(h) for h in heads)]
    except OSError:
        return []
    for name in names:
        m = next((m for h in heads if name.startswith(h)
                  and (m := _PARTIAL.fullmatch(name[len(h):])) is not None), None)
        if m is None:
            continue
        full = parent / name
        try:
            st = os.lstat(full)
        except OSError:
            continue
        if not stat.S_ISREG(st.st_mode):
            continue
        if m.group(1) is not None:
            if int(m.group(1)) == os.getpid() or _alive(int(m.group(1))):
                continue
        elif time.time() - st.st_mtime < STALE_AGE:
            continue
        try:
            fd = os.open(full, os.O_RDONLY | getattr(os, "O_CLOEXEC", 0))
        except OSError:
            continue
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            os.unlink(full)
            removed.append((name, st.st_size))
        except OSError:  # locked: a live writer (or no flock here: leave it)
            pass
        finally:
            os.close(fd)
    return removed


@contextlib.contextmanager
def atomic_path(path: str | Path, *, overwrite: bool = False) -> Iterator[Path]:
    """A temporary path next to ``path``, unique to this process, published to ``path``
    when the block ends without an exception (removed otherwise): ``publish``'s rule, so a
    file at ``path`` is replaced only with ``overwrite`` and only if it is the one
    ``check_output`` saw (or, unchecked, the one there when the block began); a file that
    appeared meanwhile is never replaced. Temporary files of killed earlier attempts are
    removed first (``clean_stale_partials``). OSErrors become OutputError.

        with atomic_path(out, overwrite=overwrite) as tmp:
            fig.savefig(tmp)
    """
    path = Path(path)
    key = os.path.abspath(path)
    old = _CHECKED.pop(key) if key in _CHECKED else file_seen(path)
    if not overwrite:
        old = None
    parent = path.parent if str(path.parent) else Path(".")
    clean_stale_partials(path)
    try:
        fd, name = tempfile.mkstemp(prefix=partial_prefix(path),
                                    suffix=f".partial{path.suffix[:9]}", dir=parent)
        os.close(fd)
    except OSError as err:
        raise OutputError(f"{shown(path)}: cannot be written ({os_reason(err)})") from None
    tmp = Path(name)
    try:
        yield tmp
        publish(tmp, path, old=old)
    except OutputError:
        raise
    except OSError as err:
        raise OutputError(f"{shown(path)}: cannot be written ({os_reason(err)})") from None
    finally:
        with contextlib.suppress(OSError):
            tmp.unlink()


def write_atomic(path: str | Path, write: Callable[[Path], None], *,
                 overwrite: bool = False) -> None:
    """``write(tmp)`` to a unique temporary file, then publish it at ``path`` (see
    ``atomic_path``: an existing file is replaced only with ``overwrite``)."""
    with atomic_path(path, overwrite=overwrite) as tmp:
        write(tmp)

"""Output files: one policy for every command that writes one (no I/O libraries here).

- An existing path is refused unless the user said ``overwrite`` (``--overwrite``).
- A path that is a command's own input is refused even with ``overwrite``: every file the
  command reads (the scene, its records and record listings, the result being plotted,
  a hazard or measured CSV), compared by the file's identity (device and inode: a
  symbolic or hard link, ``..`` or another spelling of an input is that input;
  ``is_input``). A scene lists what it read (``Scene.inputs``).
- Only regular files are written: a directory, a device (``/dev/null``, ``/dev/full``), a
  FIFO or a socket is refused even with ``overwrite``.
- The directory must exist and be writable, and the name must fit the file system.
- Files appear atomically: they are written under a temporary name unique to the process
  (``tempfile.mkstemp`` in the target's directory) and renamed over the target when
  complete (``publish``, the one rename of every output, result files included), so an
  output is either complete or absent, and two processes writing the same path never
  share a temporary file. A new file gets the mode the umask gives (``new_file_mode``).

Every refusal is an ``OutputError`` (a ``RocksweepError``) with one line naming the path
and the reason.
"""

from __future__ import annotations

import contextlib
import errno
import os
import stat
import tempfile
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path

from rocksweep.errors import OutputError


def _reason(err: OSError) -> str:
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
        return "no such file"
    except (OSError, ValueError) as err:  # ValueError: a NUL byte in the name
        return _reason(err) if isinstance(err, OSError) else "not a valid file name"
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
        raise OutputError(f"{shown(path)}: cannot be written ({_reason(err)})") from None
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
            raise OutputError(f"{shown(path)}: already exists; use --overwrite to replace it")
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


def publish(tmp: Path, path: Path, *, replace: bool = True, old_fd: int | None = None) -> None:
    """Rename the finished temporary file ``tmp`` to ``path`` with a new file's mode: the
    one rename of every output. replace: over whatever is at ``path`` (its checks were
    made, ``check_output``); else over the file held open by ``old_fd`` only if it is
    still the one at ``path``, or, without ``old_fd``, only if nothing is at ``path``
    (another process may have made it since it was checked: a hard link, which fails
    then). OutputError when another process got there first."""
    os.chmod(tmp, new_file_mode())
    if replace:
        os.replace(tmp, path)
        return
    if old_fd is not None:
        try:
            same = os.path.samestat(os.fstat(old_fd), os.stat(path))
        except OSError:
            same = False
        if not same:
            raise OutputError(f"{shown(path)}: replaced by another process meanwhile; not "
                              "overwritten")
        os.replace(tmp, path)
        return
    try:
        os.link(tmp, path)
    except FileExistsError:
        raise OutputError(f"{shown(path)}: made by another process meanwhile (a sweep "
                          "started at the same time?); not overwritten") from None
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


@contextlib.contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """A temporary path next to ``path``, unique to this process, renamed to ``path`` when
    the block ends without an exception (removed otherwise). OSErrors become OutputError.

        with atomic_path(out) as tmp:
            fig.savefig(tmp)
    """
    path = Path(path)
    parent = path.parent if str(path.parent) else Path(".")
    try:
        fd, name = tempfile.mkstemp(prefix=f".{path.stem[:40]}.", suffix=f".partial{path.suffix}",
                                    dir=parent)
        os.close(fd)
    except OSError as err:
        raise OutputError(f"{shown(path)}: cannot be written ({_reason(err)})") from None
    tmp = Path(name)
    try:
        yield tmp
        publish(tmp, path)
    except OutputError:
        raise
    except OSError as err:
        raise OutputError(f"{shown(path)}: cannot be written ({_reason(err)})") from None
    finally:
        with contextlib.suppress(OSError):
            tmp.unlink()


def write_atomic(path: str | Path, write: Callable[[Path], None]) -> None:
    """``write(tmp)`` to a unique temporary file, then rename it to ``path`` (see
    ``atomic_path``)."""
    with atomic_path(path) as tmp:
        write(tmp)

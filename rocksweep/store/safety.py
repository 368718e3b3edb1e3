"""File-system safety of the writer: space, stale temporary files, locks and
the atomic rename.

- A new file's size is known (every dataset is allocated at creation): a grid larger
  than the free space is refused before anything is written (``check_space``), and the
  whole file's space is reserved before HDF5 writes (``reserve_space``).
- A new file is made under a temporary name unique to the process
  (``outputs.partial_prefix``); those of killed attempts are removed
  (``outputs.clean_stale_partials``, as for every output).
- A writer holds HDF5's exclusive lock (``flock``) on its file; ``create`` takes the same
  lock on a file it overwrites (``lock_existing``), and holds the new file's lock before
  it is renamed into place (``publish_result``), so no two processes write one path, whatever
  ``--resume``/``--overwrite`` they are given. Without ``overwrite`` the rename is a hard
  link, which fails if another process made the path meanwhile. The rename, the new
  file's mode and the rule that an input is never an output are ``rocksweep.outputs``'s,
  as for every other output.
"""

from __future__ import annotations

import errno
import fcntl
import os
import shutil
from pathlib import Path

from rocksweep.errors import StoreError
from rocksweep.outputs import publish, shown
from rocksweep.scene.model import Scene
from rocksweep.store._common import error_reason, mib

# Free space required beyond the space a new file reserves (``space_needed``): a share of
# the file, at least this many bytes [bytes], so that a small sweep fits a small disk and
# a large one leaves room for the file system's own blocks.
SPACE_MARGIN = 64 << 10
SPACE_SHARE = 1 / 64
# Space for attribute updates of a format-1 file on resume [bytes].
UPDATE_MARGIN = 1 << 20
# Space reserved for HDF5's metadata when a file is made [bytes], beyond the datasets and
# the scene text: HDF5 fails badly when a metadata write hits a full disk (a segmentation
# fault in the next flush), so the whole file's space is reserved before it is written.
METADATA_RESERVE = 256 << 10


def reserve_space(path: Path, nbytes: int) -> None:
    """Allocate ``nbytes`` of disk space to the file at ``path`` (``posix_fallocate``):
    writes within them cannot fail for want of space. OSError(ENOSPC) if there is no
    room; file systems without the call are left as they are."""
    fd = os.open(path, os.O_WRONLY | getattr(os, "O_CLOEXEC", 0))
    try:
        os.posix_fallocate(fd, 0, nbytes)
    except OSError as err:
        if err.errno not in (errno.EOPNOTSUPP, errno.EINVAL, errno.ENOSYS):
            raise
    finally:
        os.close(fd)


def reserve_bytes(scene: Scene, nbytes: int) -> int:
    """Bytes a new result file of ``scene`` reserves: its datasets (``nbytes``), HDF5's
    metadata, the scene text and the records (each ground file, ``Scene.ground_files``,
    and the record's samples, ``_store_record``; a suite's files,
    ``_store_suite_records``): each file (gzip: at most its size) and its metadata."""
    files = list(scene.ground_files().values())
    if scene.suite is not None:
        files += scene.suite.records
    rec = sum(len(r.data) + (8 << 10) for r in files)
    if scene.record is not None:  # its samples
        rec += 8 * int(scene.record.npts) + (8 << 10)
    return nbytes + METADATA_RESERVE + 4 * len(scene.text.encode()) + rec


def space_needed(reserve: int) -> int:
    """Free space required to make a file that reserves ``reserve`` bytes: those and a
    margin that scales with them (``SPACE_SHARE``, at least ``SPACE_MARGIN``)."""
    return reserve + max(SPACE_MARGIN, int(reserve * SPACE_SHARE))


def check_space(path: Path, need: int, what: str) -> None:
    """Refuse (StoreError) when the file system of ``path`` has less than ``need`` bytes
    free."""
    parent = path.parent if str(path.parent) else Path(".")
    try:
        free = shutil.disk_usage(parent).free
    except OSError:
        return  # cannot tell: the writes themselves will say
    if free < need:
        raise StoreError(f"{shown(path)}: not enough free space for {what}: needs about "
                         f"{mib(need)} ({need} bytes), {mib(free)} free in {parent}")


def lock_existing(path: Path) -> int:
    """Open the file at ``path`` and take the exclusive lock a writer holds (HDF5 locks
    with flock); returns the descriptor. StoreError if a sweep is writing it."""
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_CLOEXEC", 0))
    except OSError as err:
        raise StoreError(f"{shown(path)}: cannot be replaced ({error_reason(err)})") from None
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        os.close(fd)
        raise StoreError(f"{shown(path)}: open for writing by another process (a sweep "
                         "still running?); not overwritten") from None
    except OSError:
        pass  # no flock on this file system: HDF5 cannot lock there either
    return fd


def publish_result(tmp: Path, path: Path, old_fd: int | None) -> None:
    """Rename the finished temporary file to ``path`` (``outputs.publish``, the one rename
    of every output): over the file locked by ``old_fd``, or, without one, only if
    nothing is at ``path`` (another process may have made it since it was checked). A
    file that appeared or was replaced meanwhile is publish's ``OutputError``, as for
    every other output."""
    publish(tmp, path, old_fd=old_fd)

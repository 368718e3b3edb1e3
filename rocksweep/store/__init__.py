"""Result files: the HDF5 sweep format (CF metadata, ``format``), the identity a resume
checks (``identity``), file-system safety (``safety``: space, stale files, locks), the
writer that survives SIGKILL and full disks (``writer.SweepFile``), the reader and its
validation (``reader.read_result``)."""

from rocksweep.store.reader import SweepResult, peek_done, read_result, stored_scene
from rocksweep.store.writer import SweepFile

__all__ = ["SweepFile", "SweepResult", "peek_done", "read_result",
           "stored_scene"]

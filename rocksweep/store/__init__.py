"""Result files: the HDF5 sweep format (CF metadata), the writer that survives SIGKILL and
full disks (``SweepFile``), the reader and its validation (``read_result``)."""

from rocksweep.store.sweepfile import (
    StoreError,
    SweepFile,
    SweepResult,
    peek_done,
    read_result,
    stored_scene,
)

__all__ = ["StoreError", "SweepFile", "SweepResult", "peek_done", "read_result",
           "stored_scene"]
